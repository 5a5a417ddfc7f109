//! Resizing the maps of a project (Image > Resize): every channel resampled by the triangle
//! filter image import uses (a tent widened by the ratio when shrinking), `k_d` and `k_s` as
//! linear values and `n` in the log space the brushes blend it in, so a resized map keeps its
//! highlights' look rather than averaging exponents. The document installs the result as one
//! undo step that swaps the whole maps (and the mesh surface baked for them) back.

use std::sync::Arc;

use image::{DynamicImage, ImageBuffer, Rgb};

use super::ModelError;
use super::layers::{Layer, LayerContent, LayerStack, PaintTile, Stamped};
use super::maps::MaterialMaps;
use super::surface::Surface;
use super::texel::{Channel, MaterialValue, decode_rgb};

/// A layer stack resampled to a new size with the mesh surface baked at that size: made on a
/// worker, installed by [`super::ImportCommand::Resize`].
#[derive(Clone, Debug)]
pub struct ResizedMaps(pub Arc<(LayerStack, Option<Arc<Surface>>)>);

impl PartialEq for ResizedMaps {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

/// Bytes a `width x height` resize holds at its peak beyond the maps it starts from: the new
/// maps stored in full (14 bytes a texel) and one channel as floats at the larger of the two
/// sizes (12 bytes a texel).
pub fn peak_bytes(from: (u32, u32), width: u32, height: u32) -> u64 {
    let texels = u64::from(width) * u64::from(height);
    let larger = texels.max(u64::from(from.0) * u64::from(from.1));
    texels * 14 + larger * 12
}

/// `maps` resampled to `width x height`.
///
/// # Errors
/// A size out of range, or the same size as now.
pub fn resized(maps: &MaterialMaps, width: u32, height: u32) -> Result<MaterialMaps, ModelError> {
    if (width, height) == (maps.width(), maps.height()) {
        return Err(ModelError::Command(format!(
            "the maps are already {width}x{height}"
        )));
    }
    let mut out = MaterialMaps::new(width, height, MaterialValue::default())?;
    for channel in Channel::ALL {
        let image = channel_image(maps, channel);
        let planes = super::import::resample_as(&image, channel, width, height, true);
        drop(image);
        super::import::write_planes(&mut out, &planes);
    }
    Ok(out)
}

/// Every layer of `stack` resampled to `width x height`: a paint layer's values and coverages
/// and a mask's gray by the same filter as the maps (coverages and grays linearly).
///
/// # Errors
/// As [`resized`].
pub fn resized_stack(
    stack: &LayerStack,
    width: u32,
    height: u32,
) -> Result<LayerStack, ModelError> {
    let mut out = stack.clone();
    out.width = width;
    out.height = height;
    let count = out.tile_count();
    resize_layers(
        &mut out.layers,
        (stack.width, stack.height),
        (width, height),
        count,
    )?;
    Ok(out)
}

fn resize_layers(
    layers: &mut [Layer],
    from: (u32, u32),
    to: (u32, u32),
    count: usize,
) -> Result<(), ModelError> {
    use super::tile::{Plane, Tile};
    let gray_maps =
        |planes: &mut dyn Iterator<Item = [Plane<u16>; 3]>| -> Result<MaterialMaps, ModelError> {
            let mut maps = MaterialMaps::new(from.0, from.1, MaterialValue::default())?;
            for (id, p) in planes.enumerate() {
                let mut tile = Tile::uniform(super::texel::Texel::default());
                let [a, b, c] = p;
                tile.kd = Plane::Data(
                    (0..super::tile::TILE_TEXELS)
                        .map(|i| [a.get(i), b.get(i), c.get(i)])
                        .collect(),
                );
                tile.kd.compact();
                maps.replace_tile(id, Arc::new(tile));
            }
            Ok(maps)
        };
    for layer in layers {
        if let Some(mask) = &mut layer.mask {
            let mut planes = mask.tiles.iter().map(|t| {
                let g = t.get().clone();
                [g.clone(), g.clone(), g]
            });
            let big = resized(&gray_maps(&mut planes)?, to.0, to.1)?;
            mask.tiles = (0..count)
                .map(|id| {
                    let mut g = Plane::Data(
                        (0..super::tile::TILE_TEXELS)
                            .map(|i| big.tile(id).kd.get(i)[0])
                            .collect(),
                    );
                    g.compact();
                    Arc::new(Stamped::new(g))
                })
                .collect();
        }
        match &mut layer.content {
            LayerContent::Paint(tiles) => {
                if tiles.iter().all(Option::is_none) {
                    *tiles = vec![None; count];
                    continue;
                }
                let empty = PaintTile::filled(MaterialValue::default(), [false; 3]);
                // Values premultiplied by their coverage, so a texel counts as much as the
                // layer covers it: what is under no paint does not darken a stroke's edge.
                let mut values = MaterialMaps::new(from.0, from.1, MaterialValue::default())?;
                for (id, t) in tiles.iter().enumerate() {
                    let t = t.as_ref().map_or(&empty, |t| t.get());
                    values.replace_tile(id, Arc::new(premultiplied(t)));
                }
                let mut alphas = tiles
                    .iter()
                    .map(|t| t.as_ref().map_or(&empty, |t| t.get()).alpha.clone());
                let alpha = resized(&gray_maps(&mut alphas)?, to.0, to.1)?;
                let values = resized(&values, to.0, to.1)?;
                *tiles = (0..count)
                    .map(|id| {
                        let a = &alpha.tile(id).kd;
                        let alpha = std::array::from_fn(|c| {
                            Plane::Data(
                                (0..super::tile::TILE_TEXELS).map(|i| a.get(i)[c]).collect(),
                            )
                        });
                        let mut tile = PaintTile {
                            value: unpremultiplied(values.tile(id), &alpha),
                            alpha,
                        };
                        tile.alpha.iter_mut().for_each(Plane::compact);
                        let empty = tile.alpha.iter().all(|p| p.uniform() == Some(0));
                        (!empty).then(|| Arc::new(Stamped::new(tile)))
                    })
                    .collect();
            }
            // Laid again on the new size by the document.
            LayerContent::Fill(_) | LayerContent::Projected(_) => {}
            LayerContent::Group(children) => resize_layers(children, from, to, count)?,
        }
    }
    Ok(())
}

/// A paint tile's values (in blend space) times their channel's coverage, as maps store them.
fn premultiplied(t: &PaintTile) -> super::tile::Tile {
    per_texel(&t.value, &t.alpha, |v, a| v * a)
}

/// Values resampled premultiplied back over their resampled coverage (0 where none).
fn unpremultiplied(
    value: &super::tile::Tile,
    alpha: &[super::tile::Plane<u16>; 3],
) -> super::tile::Tile {
    per_texel(value, alpha, |v, a| if a > 0.0 { v / a } else { 0.0 })
}

/// `value` with every component, in blend space, replaced by `f(component, its channel's
/// coverage)`.
fn per_texel(
    value: &super::tile::Tile,
    alpha: &[super::tile::Plane<u16>; 3],
    f: impl Fn(f32, f32) -> f32,
) -> super::tile::Tile {
    use super::paint::{n_bits_from_blend, n_bits_to_blend};
    use super::texel::{Texel, decode_unorm, encode_unorm};
    let texel = |i: usize| {
        let t = value.texel(i);
        let a = alpha.each_ref().map(|p| decode_unorm(p.get(i)));
        Texel {
            kd: t.kd.map(|q| encode_unorm(f(decode_unorm(q), a[0]))),
            ks: t.ks.map(|q| encode_unorm(f(decode_unorm(q), a[1]))),
            n: n_bits_from_blend(f(n_bits_to_blend(t.n), a[2])),
        }
    };
    let uniform = value.kd.uniform().is_some()
        && value.ks.uniform().is_some()
        && value.n.uniform().is_some()
        && alpha.iter().all(|p| p.uniform().is_some());
    if uniform {
        return super::tile::Tile::uniform(texel(0));
    }
    let mut out = super::tile::Tile::uniform(Texel::default());
    for i in 0..super::tile::TILE_TEXELS {
        out.set_texel(i, texel(i));
    }
    out.compact();
    out
}

/// One channel as a linear float image: `k_d` and `k_s` as they are, `n` as its blend value
/// in all three components.
fn channel_image(maps: &MaterialMaps, channel: Channel) -> DynamicImage {
    let (w, h) = (maps.width(), maps.height());
    let mut image: ImageBuffer<Rgb<f32>, Vec<f32>> = ImageBuffer::new(w, h);
    maps.for_each_texel(|x, y, t| {
        let v = match channel {
            Channel::Kd => decode_rgb(t.kd).to_array(),
            Channel::Ks => decode_rgb(t.ks).to_array(),
            Channel::N => [super::paint::n_bits_to_blend(t.n); 3],
        };
        image.put_pixel(x, y, Rgb(v));
    });
    DynamicImage::ImageRgb32F(image)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn a_uniform_map_stays_uniform_and_n_resamples_in_log_space() {
        let base = MaterialValue::new(Vec3::new(0.6, 0.2, 0.1), Vec3::splat(0.3), 90.0);
        let maps = MaterialMaps::new(128, 128, base).unwrap();
        let half = resized(&maps, 64, 96).unwrap();
        assert_eq!((half.width(), half.height()), (64, 96));
        assert_eq!(half.uniform_texel(), maps.uniform_texel());
        assert_eq!(half.heap_bytes(), 0, "uniform planes cost nothing");
        // Two columns of n = 10 and n = 1000 shrink to about their geometric middle.
        let mut maps = MaterialMaps::new(2, 1, base).unwrap();
        let tile = maps.tile_mut(0);
        let lo = crate::texel::Texel::encode(MaterialValue { n: 10.0, ..base });
        let hi = crate::texel::Texel::encode(MaterialValue { n: 1000.0, ..base });
        tile.set_texel(0, lo);
        tile.set_texel(1, hi);
        let one = resized(&maps, 1, 1).unwrap();
        let n = one.value(0, 0).n;
        assert!(
            (90.0..=112.0).contains(&n),
            "log-space mean of 10 and 1000: {n}"
        );
        assert!(resized(&one, 1, 1).is_err(), "same size");
        assert!(resized(&one, 0, 4).is_err());
    }

    /// Resizing a layer weights its values by coverage: a white stroke's edge stays white
    /// (where it is half covered), rather than mixing in the black under no paint.
    #[test]
    fn a_layer_resizes_its_values_weighted_by_coverage() {
        use crate::layers::{Layer, LayerContent, LayerStack, PaintTile, Stamped};
        let base = MaterialValue::new(Vec3::splat(0.2), Vec3::splat(0.1), 10.0);
        let mut stack = LayerStack::new(128, 64, base);
        let white = MaterialValue::new(Vec3::ONE, Vec3::splat(0.5), 1000.0);
        let mut layer = Layer::paint(String::from("Stroke"), stack.tile_count());
        if let LayerContent::Paint(tiles) = &mut layer.content {
            // The left tile painted white, the right one untouched (black, uncovered).
            tiles[0] = Some(Arc::new(Stamped::new(PaintTile::filled(white, [true; 3]))));
        }
        stack.layers = vec![layer];
        let half = resized_stack(&stack, 64, 32).unwrap();
        let LayerContent::Paint(tiles) = &half.layers[0].content else {
            panic!("a paint layer");
        };
        let tile = tiles[0].as_ref().expect("painted").get();
        // Column 32 of the half-size map straddles the edge: partly covered, still white.
        let i = 10 * crate::tile::TILE_SIZE + 32;
        let cover = crate::texel::decode_unorm(tile.alpha[0].get(i));
        assert!((0.05..0.95).contains(&cover), "edge coverage {cover}");
        let t = tile.value.texel(i).decode();
        assert!((t.kd - Vec3::ONE).abs().max_element() < 1e-3, "{t:?}");
        assert!((t.n / 1000.0 - 1.0).abs() < 0.01, "{t:?}");
    }

    #[test]
    fn doubling_then_halving_comes_back_close() {
        let mut maps = MaterialMaps::new(64, 64, MaterialValue::default()).unwrap();
        let tile = maps.tile_mut(0);
        for i in 0..64 * 64 {
            let (x, y) = ((i % 64) as f32 / 63.0, (i / 64) as f32 / 63.0);
            let v = MaterialValue::new(Vec3::new(x, y, 0.5), Vec3::splat(0.2), 1.0 + 500.0 * x);
            tile.set_texel(i, crate::texel::Texel::encode(v));
        }
        let back = resized(&resized(&maps, 128, 128).unwrap(), 64, 64).unwrap();
        for (x, y) in [(10, 10), (30, 40), (50, 20)] {
            let (a, b) = (maps.value(x, y), back.value(x, y));
            assert!((a.kd - b.kd).abs().max_element() < 0.01, "{a:?} {b:?}");
            assert!((a.n / b.n - 1.0).abs() < 0.05, "{a:?} {b:?}");
        }
    }
}
