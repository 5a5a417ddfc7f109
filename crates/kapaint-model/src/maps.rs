//! `MaterialMaps`: the per-texel `k_d`, `k_s` and `n` of a material, tiled, with versions.

use std::sync::{Arc, OnceLock};

use glam::Vec3;
use rayon::prelude::*;

use super::ModelError;
use super::texel::{Channels, MaterialValue, Texel, decode_n, decode_rgb};
use super::tile::{Plane, TILE_SIZE, TILE_TEXELS, Tile};
use kapaint_reflectance::{self as reflectance, AmbientApprox, ShadingModel};

/// Largest map side in texels.
pub const MAX_SIDE: u32 = 8192;

/// Index of a tile in row-major tile order.
pub type TileId = usize;

/// A rectangle of texels: columns `x0..x1`, rows `y0..y1` (exclusive ends).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TexelRect {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// One past the last column.
    pub x1: u32,
    /// One past the last row.
    pub y1: u32,
}

impl TexelRect {
    /// Columns covered.
    pub fn width(self) -> u32 {
        self.x1.saturating_sub(self.x0)
    }

    /// Rows covered.
    pub fn height(self) -> u32 {
        self.y1.saturating_sub(self.y0)
    }

    /// Whether it covers no texel.
    pub fn is_empty(self) -> bool {
        self.x1 <= self.x0 || self.y1 <= self.y0
    }

    /// This rectangle of level 0 at mip `level` of maps of `size`, in texels of that level:
    /// every texel of the level that a texel of the rectangle falls in, clipped to the
    /// level's size (sizes that are not powers of two round down).
    #[must_use]
    pub fn at_level(self, level: u32, size: (u32, u32)) -> Self {
        let (lw, lh) = ((size.0 >> level).max(1), (size.1 >> level).max(1));
        Self {
            x0: (self.x0 >> level).min(lw),
            y0: (self.y0 >> level).min(lh),
            x1: (self.x1.saturating_sub(1) >> level)
                .saturating_add(1)
                .min(lw),
            y1: (self.y1.saturating_sub(1) >> level)
                .saturating_add(1)
                .min(lh),
        }
    }
}

/// The next maps identity.
fn next_maps_id() -> u64 {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

impl Clone for MaterialMaps {
    /// A copy shares the tiles (copy-on-write) but is other maps: it gets its own identity.
    fn clone(&self) -> Self {
        Self {
            id: next_maps_id(),
            width: self.width,
            height: self.height,
            tiles_x: self.tiles_x,
            tiles_y: self.tiles_y,
            tiles: self.tiles.clone(),
            versions: self.versions.clone(),
            clock: self.clock,
        }
    }
}

/// The maps of one material: any size up to `MAX_SIDE` square, stored as 64 x 64 tiles.
///
/// Tiles are shared (`Arc`) so that history can keep old versions without copying: writing
/// to a tile clones it only if history still holds it. Every write bumps the versions of the
/// tile's channels it may change, so consumers (the GPU mirror, k_a caches) can ask what
/// changed since they last looked, tile by tile and channel by channel.
#[derive(Debug)]
pub struct MaterialMaps {
    /// Which maps these are: no other maps in the process had this number, so a mirror keyed
    /// on it and the version never mistakes another document's maps of the same size for
    /// these (a new or opened document is mirrored whole).
    id: u64,
    width: u32,
    height: u32,
    tiles_x: u32,
    tiles_y: u32,
    tiles: Vec<Arc<Tile>>,
    /// Per tile, the versions of its `k_d`, `k_s` and `n` planes.
    versions: Vec<[u64; 3]>,
    clock: u64,
}

impl MaterialMaps {
    /// Maps of `width x height` texels, every texel `base`.
    pub fn new(width: u32, height: u32, base: MaterialValue) -> Result<Self, ModelError> {
        if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
            return Err(ModelError::InvalidSize { width, height });
        }
        let tiles_x = width.div_ceil(TILE_SIZE as u32);
        let tiles_y = height.div_ceil(TILE_SIZE as u32);
        let count = (tiles_x * tiles_y) as usize;
        let tile = Arc::new(Tile::uniform(Texel::encode(base.sanitized())));
        Ok(Self {
            id: next_maps_id(),
            width,
            height,
            tiles_x,
            tiles_y,
            tiles: vec![tile; count],
            versions: vec![[1; 3]; count],
            clock: 1,
        })
    }

    /// Which maps these are (see the field): a copy is other maps, with another number.
    pub fn id(&self) -> u64 {
        self.id
    }

    /// Width in texels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Tiles per row.
    pub fn tiles_x(&self) -> u32 {
        self.tiles_x
    }

    /// Tiles per column.
    pub fn tiles_y(&self) -> u32 {
        self.tiles_y
    }

    /// Number of tiles.
    pub fn tile_count(&self) -> usize {
        self.tiles.len()
    }

    /// Texels in the maps.
    pub fn texel_count(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// The tile holding texel `(x, y)` and the texel's index inside it.
    #[inline]
    pub fn locate(&self, x: u32, y: u32) -> (TileId, usize) {
        let (tx, ty) = (x as usize / TILE_SIZE, y as usize / TILE_SIZE);
        let (ix, iy) = (x as usize % TILE_SIZE, y as usize % TILE_SIZE);
        (ty * self.tiles_x as usize + tx, iy * TILE_SIZE + ix)
    }

    /// The texels a tile covers in the maps.
    pub fn tile_rect(&self, id: TileId) -> TexelRect {
        let tx = (id % self.tiles_x as usize) as u32;
        let ty = (id / self.tiles_x as usize) as u32;
        let (x0, y0) = (tx * TILE_SIZE as u32, ty * TILE_SIZE as u32);
        TexelRect {
            x0,
            y0,
            x1: (x0 + TILE_SIZE as u32).min(self.width),
            y1: (y0 + TILE_SIZE as u32).min(self.height),
        }
    }

    /// The stored texel at `(x, y)`; panics outside the maps.
    #[inline]
    pub fn texel(&self, x: u32, y: u32) -> Texel {
        assert!(
            x < self.width && y < self.height,
            "texel ({x}, {y}) outside the maps"
        );
        let (id, i) = self.locate(x, y);
        self.tiles[id].texel(i)
    }

    /// The linear value at `(x, y)`; panics outside the maps.
    pub fn value(&self, x: u32, y: u32) -> MaterialValue {
        self.texel(x, y).decode()
    }

    /// Every tile, row-major (shared: a clone stroke keeps a copy of the list to read while
    /// it writes, and a write after that copies the tile it writes).
    pub fn tiles(&self) -> &[Arc<Tile>] {
        &self.tiles
    }

    /// A tile, shared.
    pub fn tile(&self, id: TileId) -> &Arc<Tile> {
        &self.tiles[id]
    }

    /// A tile for writing: cloned first if anything else (history) holds it. Bumps its version.
    pub fn tile_mut(&mut self, id: TileId) -> &mut Tile {
        self.touch(id, Channels::ALL);
        Arc::make_mut(&mut self.tiles[id])
    }

    /// Edits tiles `ids` (sorted ascending, without duplicates) in parallel: `edit(k, tile)`
    /// gets the `k`-th tile's slot, changes it copy-on-write ([`Arc::make_mut`]) or not at all,
    /// and returns the channels it changed (with anything else it has to say); only those
    /// versions move. Returns what each returned.
    pub fn edit_tiles_par<X: Send>(
        &mut self,
        ids: &[TileId],
        edit: impl Fn(usize, &mut Arc<Tile>) -> (Channels, X) + Sync,
    ) -> Vec<(Channels, X)> {
        let changed: Vec<(Channels, X)> = super::tile::select_mut(&mut self.tiles, ids)
            .into_par_iter()
            .enumerate()
            .map(|(k, tile)| edit(k, tile))
            .collect();
        for (&id, (c, _)) in ids.iter().zip(&changed) {
            if !c.is_empty() {
                self.touch(id, *c);
            }
        }
        changed
    }

    /// Several tiles for writing at once (each cloned first if shared), for parallel work on
    /// disjoint tiles. `ids` must be sorted ascending without duplicates; bumps versions.
    pub fn tiles_mut_many(&mut self, ids: &[TileId]) -> Vec<&mut Tile> {
        self.tiles_mut_many_in(ids, Channels::ALL)
    }

    /// [`MaterialMaps::tiles_mut_many`] for a writer that changes only `channels` (the other
    /// planes may be rewritten, but with the values they hold): only their versions move.
    pub fn tiles_mut_many_in(&mut self, ids: &[TileId], channels: Channels) -> Vec<&mut Tile> {
        for &id in ids {
            self.touch(id, channels);
        }
        super::tile::select_mut(&mut self.tiles, ids)
            .into_iter()
            .map(Arc::make_mut)
            .collect()
    }

    /// Puts `tile` in place of tile `id` and returns the previous one (undo and redo).
    pub fn replace_tile(&mut self, id: TileId, tile: Arc<Tile>) -> Arc<Tile> {
        self.touch(id, Channels::ALL);
        std::mem::replace(&mut self.tiles[id], tile)
    }

    /// Puts `tile` in place of tile `id`, whose planes differ only in `channels` (the
    /// compositor's write): only their versions move.
    pub fn replace_tile_in(&mut self, id: TileId, tile: Arc<Tile>, channels: Channels) {
        self.touch(id, channels);
        self.tiles[id] = tile;
    }

    /// Advances the clock and stamps `channels` of tile `id` with it.
    fn touch(&mut self, id: TileId, channels: Channels) {
        self.clock += 1;
        let on = [channels.kd, channels.ks, channels.n];
        for (version, on) in self.versions[id].iter_mut().zip(on) {
            if on {
                *version = self.clock;
            }
        }
    }

    /// Stamps every tile and channel past `version` (maps swapped in whole, by a resize or
    /// its undo: the document's version keeps growing, and mirrors see every tile changed).
    pub fn stamp_after(&mut self, version: u64) {
        self.clock = self.clock.max(version) + 1;
        let clock = self.clock;
        self.versions.iter_mut().for_each(|v| *v = [clock; 3]);
    }

    /// The current version: it grows with every write.
    pub fn version(&self) -> u64 {
        self.clock
    }

    /// The version of one tile (its latest channel).
    pub fn tile_version(&self, id: TileId) -> u64 {
        self.versions[id].into_iter().max().unwrap_or(0)
    }

    /// The channels of tile `id` written after `version`.
    pub fn channels_changed_since(&self, id: TileId, version: u64) -> Channels {
        let [kd, ks, n] = self.versions[id].map(|v| v > version);
        Channels { kd, ks, n }
    }

    /// Tiles written after `version` (pass 0 for all), ascending.
    pub fn tiles_changed_since(&self, version: u64) -> Vec<TileId> {
        (0..self.tiles.len())
            .filter(|&id| self.versions[id].iter().any(|&v| v > version))
            .collect()
    }

    /// Heap bytes of the tiles currently in the maps (uniform planes cost nothing).
    pub fn heap_bytes(&self) -> usize {
        self.tiles.iter().map(|t| t.heap_bytes()).sum()
    }

    /// The texel every texel of the maps holds, if the maps are uniform (lets the GPU and the
    /// exporter replace a map with a constant).
    pub fn uniform_texel(&self) -> Option<Texel> {
        let first = self.tiles.first()?;
        let t = Texel {
            kd: first.kd.uniform()?,
            ks: first.ks.uniform()?,
            n: first.n.uniform()?,
        };
        self.tiles
            .iter()
            .all(|tile| {
                tile.kd.uniform() == Some(t.kd)
                    && tile.ks.uniform() == Some(t.ks)
                    && tile.n.uniform() == Some(t.n)
            })
            .then_some(t)
    }

    /// Visits every texel row by row in tile order: `f(x, y, texel)`.
    pub fn for_each_texel(&self, mut f: impl FnMut(u32, u32, Texel)) {
        for id in 0..self.tiles.len() {
            let TexelRect { x0, y0, x1, y1 } = self.tile_rect(id);
            let tile = &self.tiles[id];
            for y in y0..y1 {
                for x in x0..x1 {
                    let i = (y - y0) as usize * TILE_SIZE + (x - x0) as usize;
                    f(x, y, tile.texel(i));
                }
            }
        }
    }

    /// Per channel, the value every texel holds when the channel is one value over the whole
    /// map (`k_d`, `k_s` as stored unorm16, `n` as stored half bits). Reads only the tiles'
    /// planes: a full plane makes its channel non-uniform, even if its texels happen to agree.
    pub fn uniform_channels(&self) -> (Option<[u16; 3]>, Option<[u16; 3]>, Option<u16>) {
        fn same<T: Copy + PartialEq>(
            tiles: &[Arc<Tile>],
            plane: impl Fn(&Tile) -> &super::tile::Plane<T>,
        ) -> Option<T> {
            let mut value = None;
            for tile in tiles {
                let v = plane(tile).uniform()?;
                if *value.get_or_insert(v) != v {
                    return None;
                }
            }
            value
        }
        (
            same(&self.tiles, |t| &t.kd),
            same(&self.tiles, |t| &t.ks),
            same(&self.tiles, |t| &t.n),
        )
    }

    /// Derives `k_a` for the given tiles into `out`: per tile of `ids` in turn, `TILE_TEXELS`
    /// values in row-major tile order (texels beyond the map edge included, they are well
    /// defined). Never stored. `out` is resized to fit and its old values overwritten: a
    /// caller that derives after every dab keeps one buffer, and no memory is touched for the
    /// first time on the way (fresh pages cost more than the derive itself).
    pub fn derive_ka_tiles_into(
        &self,
        model: ShadingModel,
        approx: AmbientApprox,
        ids: &[TileId],
        out: &mut Vec<Vec3>,
    ) {
        let lut = chi_lut(model, approx);
        let diffuse = reflectance::diffuse_factor(approx.for_model(model)) as f32;
        let len = ids.len() * TILE_TEXELS;
        if out.len() < len {
            out.resize(len, Vec3::ZERO);
        }
        out.truncate(len);
        out.par_chunks_mut(TILE_TEXELS)
            .zip(ids)
            .for_each(|(out, &id)| {
                kapaint_base::simd::vectorized(DeriveTile(&self.tiles[id], lut, diffuse, out));
            });
    }

    /// Derives `k_a` for the whole map into `out` (row-major, `width * height` values), in
    /// parallel over bands of tile rows, writing straight into the output rows.
    pub fn derive_ka_into(&self, model: ShadingModel, approx: AmbientApprox, out: &mut [Vec3]) {
        assert_eq!(
            out.len(),
            self.texel_count(),
            "derive_ka_into: wrong output size"
        );
        let lut = chi_lut(model, approx);
        let diffuse = reflectance::diffuse_factor(approx.for_model(model)) as f32;
        let width = self.width as usize;
        out.par_chunks_mut(width * TILE_SIZE)
            .enumerate()
            .for_each(|(ty, band)| {
                let rows = band.len() / width;
                for tx in 0..self.tiles_x as usize {
                    let tile = &self.tiles[ty * self.tiles_x as usize + tx];
                    let x0 = tx * TILE_SIZE;
                    let cols = TILE_SIZE.min(width - x0);
                    for r in 0..rows {
                        let dst = &mut band[r * width + x0..r * width + x0 + cols];
                        derive_row(tile, r * TILE_SIZE, lut, diffuse, dst);
                    }
                }
            });
    }
}

/// `k_a` of one tile. `n` is stored as a half float, so `[chi_1, chi_0]` of every possible code
/// is a 65,536-entry table (512 KiB, built once per model and approximation): one load per
/// texel.
struct DeriveTile<'a>(&'a Tile, &'a [[f32; 2]], f32, &'a mut [Vec3]);

impl kapaint_base::simd::Kernel for DeriveTile<'_> {
    type Output = ();

    #[inline(always)]
    #[expect(
        clippy::inline_always,
        reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
    )]
    fn with_simd<S: pulp::Simd>(self, _: S) {
        let Self(tile, lut, diffuse, out) = self;
        for (r, row) in out.chunks_exact_mut(TILE_SIZE).enumerate() {
            derive_row(tile, r * TILE_SIZE, lut, diffuse, row);
        }
    }
}

/// `k_a` of `out.len()` texels of a tile starting at texel index `start`.
#[inline(always)]
fn derive_row(tile: &Tile, start: usize, lut: &[[f32; 2]], diffuse: f32, out: &mut [Vec3]) {
    const SCALE: f32 = 1.0 / 65535.0;
    let d = diffuse * SCALE;
    let len = out.len();
    match (&tile.kd, &tile.ks, &tile.n) {
        (Plane::Data(kd), Plane::Data(ks), Plane::Data(n)) => {
            let (kd, ks, n) = (
                &kd[start..start + len],
                &ks[start..start + len],
                &n[start..start + len],
            );
            for (((o, kd), ks), &n) in out.iter_mut().zip(kd).zip(ks).zip(n) {
                let [slope, offset] = lut[n as usize];
                let chi = slope * SCALE;
                *o = Vec3::new(
                    d * f32::from(kd[0]) + chi * f32::from(ks[0]) + offset,
                    d * f32::from(kd[1]) + chi * f32::from(ks[1]) + offset,
                    d * f32::from(kd[2]) + chi * f32::from(ks[2]) + offset,
                );
            }
        }
        (Plane::Uniform(kd), Plane::Uniform(ks), Plane::Uniform(n)) => {
            let [slope, offset] = lut[*n as usize];
            out.fill(diffuse * decode_rgb(*kd) + decode_rgb(*ks) * slope + Vec3::splat(offset));
        }
        _ => {
            for (k, o) in out.iter_mut().enumerate() {
                let i = start + k;
                let (kd, ks) = (tile.kd.get(i), tile.ks.get(i));
                let [slope, offset] = lut[tile.n.get(i) as usize];
                let chi = slope * SCALE;
                *o = Vec3::new(
                    d * f32::from(kd[0]) + chi * f32::from(ks[0]) + offset,
                    d * f32::from(kd[1]) + chi * f32::from(ks[1]) + offset,
                    d * f32::from(kd[2]) + chi * f32::from(ks[2]) + offset,
                );
            }
        }
    }
}

/// `[chi_1, chi_0]` of every half-float code, for a model and approximation (built on first
/// use; `chi_0 = 0` but for Cook-Torrance, see [`reflectance::chi_parts_f32`]).
pub fn chi_lut(model: ShadingModel, approx: AmbientApprox) -> &'static [[f32; 2]] {
    const APPROXES: usize = AmbientApprox::ALL.len();
    static LUTS: [OnceLock<Vec<[f32; 2]>>; ShadingModel::ALL.len() * APPROXES] =
        [const { OnceLock::new() }; ShadingModel::ALL.len() * APPROXES];
    let approx = approx.for_model(model);
    let index = ShadingModel::ALL
        .iter()
        .position(|&m| m == model)
        .unwrap_or(0)
        * APPROXES
        + AmbientApprox::ALL
            .iter()
            .position(|&a| a == approx)
            .unwrap_or(0);
    LUTS[index].get_or_init(|| {
        (0..=u16::MAX)
            .map(|bits| reflectance::chi_parts_f32(model, approx, decode_n(bits)))
            .collect()
    })
}

#[cfg(test)]
mod tests;
