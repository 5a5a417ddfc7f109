//! Flattening a [`LayerStack`] into [`MaterialMaps`](crate::MaterialMaps), tile by tile.
//!
//! Per texel, bottom-up: the base (opaque), then each visible layer's enabled channels laid on
//! with their blend mode at `coverage x opacity x mask` (W3C source-over with a separable
//! blend, [`Covered::under`]). `k_d` and `k_s` composite as linear values, `n` in the log space
//! the brushes use. A group composites its children onto nothing first, then lays the result
//! over what is below like one layer. The result is encoded as the maps store it.
//!
//! Only the layers that take part at a tile are visited there: visible, not masked out, and
//! with something at that tile (a paint layer's untouched tile is nothing). [`Compositor`]
//! keeps, per tile, a signature of everything that tile's composite depends on (those layers'
//! settings and the stamps of their tiles and mask tiles there) and recomposites only the
//! tiles whose signature changed: hiding a layer recomposites only where it has paint. A tile is computed by the same
//! function either way, so the incremental result is bit-identical to flattening the whole
//! stack from scratch; a recomposited tile that comes out the same is not written, so the
//! maps' dirty tiles (and the GPU upload) stay the ones that really changed.
#![expect(
    clippy::inline_always,
    reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
)]

use super::{Covered, Layer, LayerContent, LayerStack, PaintTile, SharedPaintTile};
use crate::paint::n_bits_from_blend;
use crate::texel::{
    Texel, decode_n, decode_rgb, decode_unorm, encode_rgb, encode_unorm, n_to_blend,
};
use crate::tile::{Plane, TILE_SIZE, TILE_TEXELS, Tile, TileSpans};
use glam::Vec3;
use kapaint_base::simd::Kernel;

/// The components of `k_d`, `k_s` and `n` in a [`State`].
const PARTS: [std::ops::Range<usize>; 3] = [0..3, 3..6, 6..7];

/// A stored texel as compositing values.
fn values(t: Texel) -> [f32; 7] {
    let kd = decode_rgb(t.kd);
    let ks = decode_rgb(t.ks);
    [
        kd.x,
        kd.y,
        kd.z,
        ks.x,
        ks.y,
        ks.z,
        n_to_blend(decode_n(t.n)),
    ]
}

/// A layer as it takes part at one tile: only visible layers that cover something there
/// (a paint layer's tile, a fill, a group with such children), each with what it needs.
enum Active<'a> {
    /// A paint layer's tile.
    Paint(&'a Layer, &'a SharedPaintTile),
    /// A fill layer, its value as compositing values.
    Fill(&'a Layer, [f32; 7]),
    /// A group and its active children.
    Group(&'a Layer, Vec<Active<'a>>),
}

impl Active<'_> {
    fn layer(&self) -> &Layer {
        match self {
            Self::Paint(l, _) | Self::Fill(l, _) | Self::Group(l, _) => l,
        }
    }
}

/// The layers of `layers` that take part at tile `id`, bottom first.
fn active(layers: &[Layer], id: usize) -> Vec<Active<'_>> {
    active_at(layers, id, true)
}

/// [`active`], where `generated` says whether a generator's values may be computed to find
/// a layer its mask hides at the tile (without, such a layer counts as taking part: what the
/// compositor's signatures read, so that they cost no generator a value).
fn active_at(layers: &[Layer], id: usize, generated: bool) -> Vec<Active<'_>> {
    layers
        .iter()
        .filter(|l| {
            let p = &l.props;
            let hidden_by_mask = l.mask.as_ref().is_some_and(|m| {
                m.enabled
                    && (generated || m.generator.is_none())
                    && m.uniform(id)
                        .is_some_and(|v| if m.inverted { v == u16::MAX } else { v == 0 })
            });
            p.visible && p.opacity > 0.0 && p.channels.iter().any(|c| c.enabled) && !hidden_by_mask
        })
        .filter_map(|l| match &l.content {
            LayerContent::Paint(tiles) => tiles[id].as_ref().map(|t| Active::Paint(l, t)),
            LayerContent::Fill(v) => Some(Active::Fill(l, values(Texel::encode(*v)))),
            LayerContent::Projected(p) => p.tile(id).map(|t| Active::Paint(l, t)),
            LayerContent::Group(children) => {
                let inner = active_at(children, id, generated);
                (!inner.is_empty()).then_some(Active::Group(l, inner))
            }
        })
        .collect()
}

/// A tile (or one texel of it) being composited, a plane per component (`k_d` RGB, `k_s` RGB,
/// `n` in log space): values (not premultiplied) and coverage.
struct Planes {
    value: [Vec<f32>; 7],
    /// Per component, the coverage; `None` where every texel is covered (the stack over its
    /// opaque base, which stays opaque whatever is laid on it).
    alpha: Option<[Vec<f32>; 7]>,
}

/// Texels of a tile encoded as the maps store them, a plane per channel, row by row.
struct Encoded {
    kd: Vec<[u16; 3]>,
    ks: Vec<[u16; 3]>,
    n: Vec<u16>,
}

impl Drop for Planes {
    fn drop(&mut self) {
        let alpha = self.alpha.take().into_iter().flatten();
        for v in self.value.iter_mut().map(std::mem::take).chain(alpha) {
            scratch::recycle(v);
        }
    }
}

impl Planes {
    /// `len` texels of nothing (the start of a group).
    fn clear(len: usize) -> Self {
        Self {
            value: std::array::from_fn(|_| scratch::buffer(len, 0.0)),
            alpha: Some(std::array::from_fn(|_| scratch::buffer(len, 0.0))),
        }
    }

    /// `len` texels of `base`, opaque.
    #[inline(always)]
    fn opaque(base: &[f32; 7], len: usize) -> Self {
        Self {
            value: std::array::from_fn(|k| scratch::buffer(len, base[k])),
            alpha: None,
        }
    }

    /// Every entry encoded as the maps store it (as [`Self::texel`]), appended to `out`.
    #[inline(always)]
    fn encode_into(&self, out: &mut Encoded) {
        let [r, g, b, sr, sg, sb, n] = &self.value;
        encode_rgb_planes([r, g, b], &mut out.kd);
        encode_rgb_planes([sr, sg, sb], &mut out.ks);
        let table = crate::paint::n_bits_table();
        out.n.extend(
            n.iter()
                .map(|&v| crate::paint::n_bits_from_blend_in(table, v)),
        );
    }

    /// Entry `j` encoded as the maps store it.
    #[inline]
    fn texel(&self, j: usize) -> Texel {
        let v = &self.value;
        Texel {
            kd: encode_rgb(Vec3::new(v[0][j], v[1][j], v[2][j])),
            ks: encode_rgb(Vec3::new(v[3][j], v[4][j], v[5][j])),
            // The brushes' table from log space to half floats (exact to well within a half
            // float's step).
            n: n_bits_from_blend(v[6][j]),
        }
    }
}

/// Planes of red, green and blue encoded as the maps store them, as triples appended to
/// `out`: a plane at a time through a short buffer (a loop that vectorises), then interleaved.
#[inline(always)]
fn encode_rgb_planes(planes: [&[f32]; 3], out: &mut Vec<[u16; 3]>) {
    const CHUNK: usize = 64;
    let from = out.len();
    out.resize(from + planes[0].len(), [0; 3]);
    let mut q = [[0_u16; CHUNK]; 3];
    for (at, o) in out[from..].chunks_mut(CHUNK).enumerate() {
        let range = at * CHUNK..at * CHUNK + o.len();
        for (q, p) in q.iter_mut().zip(planes) {
            for (d, &v) in q.iter_mut().zip(&p[range.clone()]) {
                *d = encode_unorm(v);
            }
        }
        let [r, g, b] = &q;
        for (((o, &r), &g), &b) in o.iter_mut().zip(r).zip(g).zip(b) {
            *o = [r, g, b];
        }
    }
}

/// Lays `src` (values at coverage `cover`) over component `dst` (its values, and its
/// coverage unless it is opaque) with `mode`, texel by texel: [`Covered::under`], with the
/// mode chosen once for the whole run.
#[inline(always)]
fn lay_plane(
    (dst_v, dst_a): (&mut [f32], Option<&mut [f32]>),
    src: &[f32],
    cover: &[f32],
    mode: super::LayerBlend,
) {
    use super::LayerBlend as B;
    #[inline(always)]
    fn run(
        mix: impl Fn(f32, f32) -> f32 + Copy,
        dst_v: &mut [f32],
        dst_a: Option<&mut [f32]>,
        src: &[f32],
        cover: &[f32],
    ) {
        let Some(dst_a) = dst_a else {
            for ((v, &s), &c) in dst_v.iter_mut().zip(src).zip(cover) {
                *v = Covered::over_opaque_with(*v, Covered { value: s, alpha: c }, mix);
            }
            return;
        };
        for (((v, a), &s), &c) in dst_v.iter_mut().zip(dst_a.iter_mut()).zip(src).zip(cover) {
            let below = Covered {
                value: *v,
                alpha: *a,
            };
            let out = below.under_with(Covered { value: s, alpha: c }, mix);
            (*v, *a) = (out.value, out.alpha);
        }
    }
    // One loop per mode, each with its blend inlined.
    match mode {
        B::Normal => run(|b, l| B::Normal.mix(b, l), dst_v, dst_a, src, cover),
        B::Multiply => run(|b, l| B::Multiply.mix(b, l), dst_v, dst_a, src, cover),
        B::Screen => run(|b, l| B::Screen.mix(b, l), dst_v, dst_a, src, cover),
        B::Overlay => run(|b, l| B::Overlay.mix(b, l), dst_v, dst_a, src, cover),
        B::Add => run(|b, l| B::Add.mix(b, l), dst_v, dst_a, src, cover),
        B::Subtract => run(|b, l| B::Subtract.mix(b, l), dst_v, dst_a, src, cover),
        B::Darken => run(|b, l| B::Darken.mix(b, l), dst_v, dst_a, src, cover),
        B::Lighten => run(|b, l| B::Lighten.mix(b, l), dst_v, dst_a, src, cover),
    }
}

/// The texels a [`Planes`] holds: spans of rows of the tile, as contiguous runs `(first texel
/// in the tile, first entry in the planes, length)`; whole rows one after another are one run.
fn runs(spans: &TileSpans) -> Vec<(usize, usize, usize)> {
    let mut out: Vec<(usize, usize, usize)> = Vec::new();
    let mut at = 0;
    for (y, x0, x1) in spans.rows() {
        let (start, len) = (y * TILE_SIZE + x0, x1 - x0);
        match out.last_mut() {
            Some(last) if last.0 + last.2 == start => last.2 += len,
            _ => out.push((start, at, len)),
        }
        at += len;
    }
    out
}

/// Decodes `plane` at the texels of `runs` into `out` through `f` (one entry a texel), a run
/// at a time.
#[inline(always)]
fn decode_runs<T: Copy + PartialEq>(
    plane: &Plane<T>,
    runs: &[(usize, usize, usize)],
    out: &mut [f32],
    f: impl Fn(T) -> f32,
) {
    for &(start, at, len) in runs {
        plane.decode_into(start, &mut out[at..at + len], &f);
    }
}

/// What the texels of `runs` of a mask show of its layer (opacity included), into `out`.
#[inline(always)]
fn cover_of(layer: &Layer, id: usize, runs: &[(usize, usize, usize)], out: &mut [f32]) {
    let opacity = layer.props.opacity.clamp(0.0, 1.0);
    match &layer.mask {
        Some(mask) if mask.enabled => {
            let plane = mask.plane(id);
            if mask.inverted {
                decode_runs(&plane, runs, out, |m| opacity * (1.0 - decode_unorm(m)));
            } else {
                decode_runs(&plane, runs, out, |m| opacity * decode_unorm(m));
            }
        }
        _ => out.fill(opacity),
    }
}

/// Channel `c` (`k_d`, `k_s` or `n`) of a paint tile at the texels of `runs`, as compositing
/// values, into `out` (its first plane for `n`), a texel's components in one pass.
#[inline(always)]
fn channel_values(
    tile: &PaintTile,
    c: usize,
    runs: &[(usize, usize, usize)],
    out: &mut [Vec<f32>; 3],
) {
    let rgb = match c {
        0 => &tile.value.kd,
        1 => &tile.value.ks,
        _ => {
            let table = crate::paint::n_blend_table();
            decode_runs(&tile.value.n, runs, &mut out[0], |bits| {
                table[bits as usize]
            });
            return;
        }
    };
    let [r, g, b] = out;
    for &(start, at, len) in runs {
        let run = [
            &mut r[at..at + len],
            &mut g[at..at + len],
            &mut b[at..at + len],
        ];
        rgb.decode_rgb_into(start, run);
    }
}

/// Lays the active layers (bottom first) over `state`: the texels of `runs` of tile `id`.
fn apply(state: &mut Planes, layers: &[Active<'_>], id: usize, runs: &[(usize, usize, usize)]) {
    apply_inline(state, layers, id, runs);
}

/// [`apply`], inlined where it is called (a group's children go through [`apply`]).
#[inline(always)]
fn apply_inline(
    state: &mut Planes,
    layers: &[Active<'_>],
    id: usize,
    runs: &[(usize, usize, usize)],
) {
    let len = state.value[0].len();
    debug_assert_eq!(
        len,
        runs.iter().map(|r| r.2).sum::<usize>(),
        "one plane entry per texel"
    );
    // Each is written whole before it is read: a layer's cover, a channel's coverage and a
    // component's values.
    let mut cover = scratch::overwritten(len);
    let mut alpha = scratch::overwritten(len);
    let mut src: [Vec<f32>; 3] = std::array::from_fn(|_| scratch::overwritten(len));
    for a in layers {
        let layer = a.layer();
        cover_of(layer, id, runs, &mut cover);
        let inner = match a {
            Active::Group(_, children) => {
                let mut inner = Planes::clear(len);
                apply(&mut inner, children, id, runs);
                Some(inner)
            }
            _ => None,
        };
        for (c, part) in PARTS.iter().enumerate() {
            let blend = layer.props.channels[c];
            if !blend.enabled {
                continue;
            }
            // The channel's coverage here (a paint layer's and a fill's are one for the
            // channel; a group's is per component), and a paint layer's values.
            match a {
                Active::Paint(_, tile) => {
                    let tile = tile.get();
                    decode_runs(&tile.alpha[c], runs, &mut alpha, decode_unorm);
                    alpha.iter_mut().zip(&cover).for_each(|(al, cv)| *al *= cv);
                    channel_values(tile, c, runs, &mut src);
                }
                Active::Fill(..) => alpha.copy_from_slice(&cover),
                Active::Group(..) => {}
            }
            for (j, k) in part.clone().enumerate() {
                let from: &[f32] = match a {
                    Active::Paint(..) => &src[j],
                    Active::Fill(_, v) => {
                        src[0].fill(v[k]);
                        &src[0]
                    }
                    Active::Group(..) => {
                        let inner = inner.as_ref().unwrap_or_else(|| unreachable!());
                        let inner_alpha = inner.alpha.as_ref().unwrap_or_else(|| unreachable!());
                        for ((al, ia), cv) in alpha.iter_mut().zip(&inner_alpha[k]).zip(&cover) {
                            *al = ia * cv;
                        }
                        &inner.value[k]
                    }
                };
                let v = &mut state.value[k];
                let al = state.alpha.as_mut().map(|a| a[k].as_mut_slice());
                lay_plane((v, al), from, &alpha, blend.mode);
            }
        }
    }
    for v in [cover, alpha].into_iter().chain(src) {
        scratch::recycle(v);
    }
}

/// Whether every input of the active layers at tile `id` is one value over the tile (then
/// one texel stands for all).
#[inline(always)]
fn uniform_inputs(layers: &[Active<'_>], id: usize) -> bool {
    layers.iter().all(|a| {
        let mask = a
            .layer()
            .mask
            .as_ref()
            .is_none_or(|m| !m.enabled || m.uniform(id).is_some());
        mask && match a {
            Active::Paint(_, t) => {
                let t = t.get();
                t.value.kd.uniform().is_some()
                    && t.value.ks.uniform().is_some()
                    && t.value.n.uniform().is_some()
                    && t.alpha.iter().all(|a| a.uniform().is_some())
            }
            Active::Fill(..) => true,
            Active::Group(_, children) => uniform_inputs(children, id),
        }
    })
}

/// The composite of tile `id`, compacted (a tile of one value is stored as one value).
#[inline(always)]
pub fn composite_tile(stack: &LayerStack, id: usize) -> Tile {
    composite_active(stack, &active(&stack.layers, id), id)
}

#[inline(always)]
fn composite_active(stack: &LayerStack, layers: &[Active<'_>], id: usize) -> Tile {
    match composited(stack, layers, id, &TileSpans::FULL) {
        Composite::Uniform(t) => Tile::uniform(t),
        Composite::Texels(e) => {
            let mut tile = Tile {
                kd: Plane::Data(e.kd.into_boxed_slice()),
                ks: Plane::Data(e.ks.into_boxed_slice()),
                n: Plane::Data(e.n.into_boxed_slice()),
            };
            tile.compact();
            tile
        }
    }
}

/// Texels `spans` of tile `id`'s composite, row by row.
#[inline(always)]
fn composite_spans(stack: &LayerStack, id: usize, spans: &TileSpans) -> Encoded {
    match composited(stack, &active(&stack.layers, id), id, spans) {
        Composite::Uniform(t) => {
            let count = spans.count();
            Encoded {
                kd: vec![t.kd; count],
                ks: vec![t.ks; count],
                n: vec![t.n; count],
            }
        }
        Composite::Texels(e) => e,
    }
}

/// [`composite_tile`] as a [`Kernel`].
struct CompositeTile<'a>(&'a LayerStack, usize);

impl Kernel for CompositeTile<'_> {
    type Output = Tile;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) -> Tile {
        composite_tile(self.0, self.1)
    }
}

/// A composite of some texels of a tile.
enum Composite {
    /// Every input is one value over the tile: so is the composite.
    Uniform(Texel),
    /// The texels, row by row.
    Texels(Encoded),
}

/// The active `layers` over the stack's base at texels `spans` of tile `id`.
#[inline(always)]
fn composited(
    stack: &LayerStack,
    layers: &[Active<'_>],
    id: usize,
    spans: &TileSpans,
) -> Composite {
    let base = values(Texel::encode(stack.base));
    if uniform_inputs(layers, id) {
        let mut state = Planes::opaque(&base, 1);
        apply(&mut state, layers, id, &runs(&TileSpans::texel(0)));
        return Composite::Uniform(state.texel(0));
    }
    let count = spans.count();
    let mut out = Encoded {
        kd: Vec::with_capacity(count),
        ks: Vec::with_capacity(count),
        n: Vec::with_capacity(count),
    };
    let mut state = Planes::opaque(&base, count);
    apply_inline(&mut state, layers, id, &runs(spans));
    state.encode_into(&mut out);
    Composite::Texels(out)
}

/// `layers` composited onto nothing at tile `id`, as a paint tile (`None` where none of them
/// covers anything): what merging them into one paint layer keeps.
pub fn merge_tile(layers: &[Layer], id: usize) -> Option<PaintTile> {
    let act = active(layers, id);
    if act.is_empty() {
        return None;
    }
    let spans = if uniform_inputs(&act, id) {
        TileSpans::texel(0)
    } else {
        TileSpans::FULL
    };
    let len = spans.count();
    let mut state = Planes::clear(len);
    apply(&mut state, &act, id, &runs(&spans));
    let mut tile = PaintTile::filled(crate::texel::MaterialValue::default(), [false; 3]);
    let planes = state.alpha.as_ref().unwrap_or_else(|| unreachable!());
    let alpha = |k: usize, i: usize| encode_unorm(planes[k][i]);
    let texel = |i: usize| state.texel(i);
    if len == 1 {
        tile.value = Tile::uniform(texel(0));
        tile.alpha = [0, 3, 6].map(|k| Plane::Uniform(alpha(k, 0)));
        return Some(tile);
    }
    for i in 0..TILE_TEXELS {
        tile.value.set_texel(i, texel(i));
        for (c, k) in [0, 3, 6].into_iter().enumerate() {
            tile.alpha[c].data_mut()[i] = alpha(k, i);
        }
    }
    tile.value.compact();
    tile.alpha.iter_mut().for_each(Plane::compact);
    Some(tile)
}

mod incremental;
mod scratch;
pub use incremental::Compositor;

#[cfg(test)]
mod tests;
