use std::sync::Arc;

use glam::Vec3;
use proptest::prelude::*;

use super::*;
use crate::layers::{ChannelBlend, LayerBlend, Mask, PaintTile, Stamped};
use crate::maps::MaterialMaps;
use crate::texel::{Channel, MaterialValue};
use crate::tile::{Plane, TILE_SIZE, TileSpans};

/// A small deterministic generator (xorshift), so one proptest seed makes one whole stack.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn unit(&mut self) -> f32 {
        (self.next() % 10_001) as f32 / 10_000.0
    }
    fn chance(&mut self, p: f32) -> bool {
        self.unit() < p
    }
    fn value(&mut self) -> MaterialValue {
        MaterialValue::new(
            Vec3::new(self.unit(), self.unit(), self.unit()),
            Vec3::splat(self.unit()),
            (self.unit() * 14.0).exp2() - 1.0,
        )
    }
    fn plane(&mut self) -> Plane<u16> {
        let mut p = Plane::Uniform((self.next() & 0xffff) as u16);
        if self.chance(0.6) {
            let data = p.data_mut();
            for _ in 0..=self.below(300) {
                data[self.below(TILE_TEXELS)] = (self.next() & 0xffff) as u16;
            }
        }
        p
    }
    fn mode(&mut self, channel: Channel) -> LayerBlend {
        loop {
            let m = LayerBlend::ALL[self.below(8)];
            if m.allowed_for(channel) {
                return m;
            }
        }
    }
}

/// Paints a few random texels (values and coverage) into tile `id` of a paint layer.
fn scribble(rng: &mut Rng, layer: &mut Layer, id: usize) {
    let texels: Vec<(usize, Texel, [u16; 3])> = (0..=rng.below(200))
        .map(|_| {
            let alpha = [0; 3].map(|_: u16| (rng.next() & 0xffff) as u16);
            (rng.below(TILE_TEXELS), Texel::encode(rng.value()), alpha)
        })
        .collect();
    if let Some(tile) = layer.paint_tile_mut(id) {
        for (i, t, alpha) in texels {
            tile.value.set_texel(i, t);
            for (plane, a) in tile.alpha.iter_mut().zip(alpha) {
                plane.data_mut()[i] = a;
            }
        }
    }
}

fn random_layer(rng: &mut Rng, tiles: usize, depth: u32) -> Layer {
    let mut layer = match rng.below(if depth == 0 { 3 } else { 2 }) {
        0 => {
            let mut l = Layer::paint("paint", tiles);
            for id in 0..tiles {
                if rng.chance(0.6) {
                    scribble(rng, &mut l, id);
                }
            }
            l
        }
        1 => Layer::fill("fill", rng.value()),
        _ => Layer::group(
            "group",
            (0..=rng.below(3))
                .map(|_| random_layer(rng, tiles, depth + 1))
                .collect(),
        ),
    };
    layer.props.visible = rng.chance(0.85);
    layer.props.opacity = if rng.chance(0.5) { 1.0 } else { rng.unit() };
    for (c, channel) in [Channel::Kd, Channel::Ks, Channel::N]
        .into_iter()
        .enumerate()
    {
        layer.props.channels[c] = ChannelBlend {
            enabled: rng.chance(0.8),
            mode: rng.mode(channel),
        };
    }
    if rng.chance(0.4) {
        let mut mask = Mask::white(tiles);
        for t in &mut mask.tiles {
            if rng.chance(0.5) {
                *t = Arc::new(Stamped::new(rng.plane()));
            }
        }
        mask.inverted = rng.chance(0.3);
        mask.enabled = rng.chance(0.9);
        layer.mask = Some(mask);
    }
    layer
}

/// Every layer of the stack, depth first, by index path.
fn layer_mut<'a>(layers: &'a mut [Layer], rng: &mut Rng) -> &'a mut Layer {
    let i = rng.below(layers.len());
    let descend =
        matches!(&layers[i].content, LayerContent::Group(c) if !c.is_empty()) && rng.chance(0.5);
    if descend {
        let LayerContent::Group(children) = &mut layers[i].content else {
            unreachable!("checked above");
        };
        return layer_mut(children, rng);
    }
    &mut layers[i]
}

/// One random edit: paint, a mask stroke, or a setting.
fn edit(rng: &mut Rng, stack: &mut LayerStack) {
    let tiles = stack.tile_count();
    let layer = layer_mut(&mut stack.layers, rng);
    match rng.below(6) {
        0 | 1 => {
            let id = rng.below(tiles);
            scribble(rng, layer, id);
        }
        2 => layer.props.visible = !layer.props.visible,
        3 => layer.props.opacity = rng.unit(),
        4 => {
            let c = rng.below(3);
            let channel = [Channel::Kd, Channel::Ks, Channel::N][c];
            layer.props.channels[c].mode = rng.mode(channel);
        }
        _ => match &mut layer.mask {
            Some(mask) if rng.chance(0.5) => {
                let id = rng.below(tiles);
                let texels: Vec<(usize, u16)> = (0..50)
                    .map(|_| (rng.below(TILE_TEXELS), (rng.next() & 0xffff) as u16))
                    .collect();
                let plane = Stamped::write(&mut mask.tiles[id]);
                for (i, v) in texels {
                    plane.data_mut()[i] = v;
                }
            }
            Some(mask) => mask.inverted = !mask.inverted,
            None => layer.mask = Some(Mask::white(tiles)),
        },
    }
}

/// The whole stack flattened from scratch.
fn flattened(stack: &LayerStack) -> MaterialMaps {
    let mut maps =
        MaterialMaps::new(stack.width, stack.height, MaterialValue::default()).expect("size");
    Compositor::new().update(stack, &mut maps);
    maps
}

fn same(a: &MaterialMaps, b: &MaterialMaps) -> bool {
    (0..a.tile_count()).all(|id| **a.tile(id) == **b.tile(id))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// After any edits, recompositing only what changed gives the maps bit for bit as
    /// flattening the whole stack from scratch; tiles whose inputs did not change are not
    /// written.
    #[test]
    fn incremental_compositing_is_bit_identical_to_a_full_flatten(seed in 1u64.., edits in 1usize..8) {
        let mut rng = Rng(seed);
        let size = if rng.chance(0.5) { (128, 128) } else { (100, 70) };
        let (mut stack, mut maps, mut compositor) = composited_stack(&mut rng, size);
        let tiles = stack.tile_count();
        prop_assert!(same(&maps, &flattened(&stack)));
        for _ in 0..edits {
            edit(&mut rng, &mut stack);
            let versions: Vec<u64> = (0..tiles).map(|id| maps.tile_version(id)).collect();
            let written = compositor.update(&stack, &mut maps);
            prop_assert!(same(&maps, &flattened(&stack)));
            for (id, version) in versions.iter().enumerate() {
                if !written.contains(&id) {
                    prop_assert_eq!(maps.tile_version(id), *version, "tile {} rewritten", id);
                }
            }
            // Looking at every tile again finds nothing (a stroke's tiles alone would do).
            prop_assert!(compositor.update_tiles(&stack, &mut maps, &(0..tiles).collect::<Vec<_>>()).is_empty());
            // Nothing changed, nothing written.
            prop_assert!(compositor.update(&stack, &mut maps).is_empty());
        }
    }
}

/// A random stack of up to four layers of `size`, with maps composited from it.
fn composited_stack(rng: &mut Rng, (w, h): (u32, u32)) -> (LayerStack, MaterialMaps, Compositor) {
    let mut stack = LayerStack::new(w, h, rng.value());
    let tiles = stack.tile_count();
    stack.layers.clear();
    for _ in 0..=rng.below(4) {
        stack.layers.push(random_layer(rng, tiles, 0));
    }
    let mut maps = MaterialMaps::new(w, h, MaterialValue::default()).expect("size");
    let mut compositor = Compositor::new();
    compositor.update(&stack, &mut maps);
    (stack, maps, compositor)
}

/// Random texels of a tile as a dab writes them: a run of columns in some rows.
fn random_spans(rng: &mut Rng) -> TileSpans {
    let mut spans = TileSpans::EMPTY;
    let (y0, y1) = (rng.below(TILE_SIZE), rng.below(TILE_SIZE));
    for y in y0.min(y1)..=y0.max(y1) {
        if rng.chance(0.8) {
            let x0 = rng.below(TILE_SIZE);
            let x1 = x0 + rng.below(TILE_SIZE - x0);
            spans.include(y * TILE_SIZE + x0);
            spans.include(y * TILE_SIZE + x1);
        }
    }
    if spans.is_empty() {
        spans.include(rng.below(TILE_SIZE * TILE_SIZE));
    }
    spans
}

/// Writes random values, coverages or mask grays inside `spans` of tile `id` of a random
/// layer (as one dab would).
fn scribble_in(rng: &mut Rng, stack: &mut LayerStack, id: usize, spans: &TileSpans) {
    let layer = layer_mut(&mut stack.layers, rng);
    let texels: Vec<usize> = spans.indices().filter(|_| rng.chance(0.7)).collect();
    if rng.chance(0.3)
        && let Some(mask) = &mut layer.mask
    {
        let plane = Stamped::write(&mut mask.tiles[id]);
        for i in texels {
            plane.data_mut()[i] = (rng.next() & 0xffff) as u16;
        }
    } else if let Some(tile) = layer.paint_tile_mut(id) {
        for i in texels {
            tile.value.set_texel(i, Texel::encode(rng.value()));
            for plane in &mut tile.alpha {
                plane.data_mut()[i] = (rng.next() & 0xffff) as u16;
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// An edit inside row spans of tiles that were composited up to date, recomposited only
    /// in those spans, gives the maps bit for bit as flattening the whole stack from
    /// scratch; the other tiles are not written.
    #[test]
    fn recompositing_only_what_a_dab_wrote_is_bit_identical(seed in 1u64.., dabs in 1usize..8) {
        let mut rng = Rng(seed);
        let (mut stack, mut maps, mut compositor) = composited_stack(&mut rng, (128, 128));
        let tiles = stack.tile_count();
        for _ in 0..dabs {
            let ids = [rng.below(tiles)];
            let spans = random_spans(&mut rng);
            prop_assert_eq!(compositor.current(&stack, &ids), vec![true]);
            scribble_in(&mut rng, &mut stack, ids[0], &spans);
            let versions: Vec<u64> = (0..tiles).map(|id| maps.tile_version(id)).collect();
            let written = compositor.update_regions(&stack, &mut maps, &[(ids[0], spans)]);
            prop_assert!(same(&maps, &flattened(&stack)));
            for (id, version) in versions.iter().enumerate() {
                if id != ids[0] {
                    prop_assert_eq!(maps.tile_version(id), *version, "tile {} rewritten", id);
                }
            }
            prop_assert!(written.len() <= 1);
            prop_assert!(compositor.update(&stack, &mut maps).is_empty(), "all up to date");
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 48,
        ..ProptestConfig::default()
    })]

    /// The compositor runs tiles through `simd::vectorized` (AVX2 where the CPU has it);
    /// the same function called plainly is compiled for baseline x86-64.
    #[test]
    fn a_vectorized_composite_is_bit_identical_to_the_baseline(seed in 1u64..) {
        let mut rng = Rng(seed);
        let (stack, _, _) = composited_stack(&mut rng, (192, 130));
        for id in 0..stack.tile_count() {
            let wide = kapaint_base::simd::vectorized(CompositeTile(&stack, id));
            prop_assert_eq!(&wide, &composite_tile(&stack, id), "tile {}", id);
        }
    }
}

#[test]
fn a_new_stack_is_its_base_and_an_empty_layer() {
    let base = MaterialValue::new(Vec3::new(0.5, 0.25, 0.1), Vec3::splat(0.3), 40.0);
    let stack = LayerStack::new(256, 256, base);
    assert_eq!(stack.layers.len(), 1);
    assert_eq!(stack.layers[0].props.name, "Layer 1");
    assert_eq!(stack.heap_bytes(), 0, "an empty layer costs no tile memory");
    let maps = flattened(&stack);
    assert_eq!(maps.uniform_texel(), Some(Texel::encode(base)));
}

#[test]
fn ka_comes_from_the_composite_not_from_blending_ka() {
    use kapaint_reflectance::{AmbientApprox, ShadingModel, ka};
    // A gloss layer at 50 % changing only n, from 10 to 2000, over a grey base.
    let base = MaterialValue::new(Vec3::splat(0.4), Vec3::splat(0.5), 10.0);
    let mut stack = LayerStack::new(64, 64, base);
    let gloss = MaterialValue { n: 2000.0, ..base };
    stack.layers[0] = Layer::fill("gloss", gloss);
    stack.layers[0].props.opacity = 0.5;
    stack.layers[0].props.channels[0].enabled = false;
    stack.layers[0].props.channels[1].enabled = false;
    let v = flattened(&stack).value(0, 0);
    let (m, a) = (ShadingModel::Phong, AmbientApprox::Fast);
    let of_composite = ka(m, a, v.kd, v.ks, v.n).x;
    let naive =
        0.5 * ka(m, a, base.kd, base.ks, base.n).x + 0.5 * ka(m, a, gloss.kd, gloss.ks, gloss.n).x;
    // n composites in log space to about sqrt(11 x 2001) - 1 = 147.
    assert!((v.n - 147.0).abs() < 2.0, "{}", v.n);
    // k_a (red) of the composite is 0.2608; half of each layer's k_a would be 0.2841, 8.9 %
    // too bright: chi(n) is not linear in log n.
    assert!((of_composite - 0.2608).abs() < 1e-3, "{of_composite}");
    assert!((naive - 0.2841).abs() < 1e-3, "{naive}");
    let gap = (naive - of_composite) / of_composite;
    assert!(
        gap > 0.08,
        "k_a of the composite {of_composite}, naive blend {naive}: {gap}"
    );
}

#[test]
fn a_channel_disabled_or_a_hidden_layer_leaves_the_maps_as_below() {
    let base = MaterialValue::new(Vec3::splat(0.2), Vec3::splat(0.1), 8.0);
    let mut stack = LayerStack::new(64, 64, base);
    let red = MaterialValue::new(Vec3::new(1.0, 0.0, 0.0), Vec3::splat(0.9), 900.0);
    let layer = &mut stack.layers[0];
    let tile = layer.paint_tile_mut(0).expect("paint layer");
    *tile = PaintTile::filled(red, [true, false, true]);
    let painted = flattened(&stack).value(5, 5);
    assert_eq!(painted.kd, Texel::encode(red).decode().kd);
    assert_eq!(
        painted.ks,
        Texel::encode(base).decode().ks,
        "k_s not covered"
    );
    stack.layers[0].props.visible = false;
    assert_eq!(flattened(&stack).uniform_texel(), Some(Texel::encode(base)));
}

#[test]
fn a_stroke_recomposites_the_tiles_it_names() {
    let mut stack = LayerStack::new(128, 128, MaterialValue::default());
    let mut maps = MaterialMaps::new(128, 128, MaterialValue::default()).expect("size");
    let mut compositor = Compositor::new();
    compositor.update(&stack, &mut maps);
    let red = MaterialValue::new(Vec3::new(1.0, 0.0, 0.0), Vec3::splat(0.2), 50.0);
    *stack.layers[0].paint_tile_mut(3).expect("paint layer") = PaintTile::filled(red, [true; 3]);
    assert_eq!(compositor.update_tiles(&stack, &mut maps, &[3]), vec![3]);
    assert!(same(&maps, &flattened(&stack)));
    assert!(
        compositor.update(&stack, &mut maps).is_empty(),
        "nothing left"
    );
}
