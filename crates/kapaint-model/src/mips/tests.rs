//! Tests of the mip sums, without a device.

use super::*;

/// Rows of one level kept in memory: what a staging buffer holds, without a device.
struct StagedLevel {
    level: u32,
    width: usize,
    kd: Vec<u16>,
    ks: Vec<u16>,
    n: Vec<u16>,
}

impl MipRows for StagedLevel {
    fn level(&self) -> u32 {
        self.level
    }

    fn origin(&self) -> (u32, u32) {
        (0, 0)
    }

    fn staged(&self, _: Channel) -> bool {
        true
    }

    fn put(&mut self, channel: Channel, (x, y): (usize, usize), row: &[u16]) {
        let (out, words) = match channel {
            Channel::Kd => (&mut self.kd, 4),
            Channel::Ks => (&mut self.ks, 4),
            Channel::N => (&mut self.n, 1),
        };
        let at = y * self.width * words + x;
        out[at..at + row.len()].copy_from_slice(row);
    }
}

/// Every level of a partial tile (45 x 30 texels at a map's edge) written through
/// `MipRows` is the box mean of its level-0 texels, rounded once: `k_d` and `k_s` as
/// unorm16 codes (half up), `n` as a half float of the mean.
#[test]
fn tile_mips_are_the_box_means_of_level_zero_without_a_device() {
    let (w, h) = (45_usize, 30_usize);
    let code = |i: usize, c: usize| ((i * 7919 + c * 104_729) % 65_536) as u16;
    let kd: Vec<[u16; 3]> = (0..TILE_SIZE * TILE_SIZE)
        .map(|i| [code(i, 0), code(i, 1), code(i, 2)])
        .collect();
    let ks: Vec<[u16; 3]> = (0..TILE_SIZE * TILE_SIZE)
        .map(|i| [code(i, 3), code(i, 4), code(i, 5)])
        .collect();
    let n_of = |i: usize| ((i % 97) as f32).powi(2);
    let n: Vec<u16> = (0..TILE_SIZE * TILE_SIZE)
        .map(|i| half::f16::from_f32(n_of(i)).to_bits())
        .collect();
    let tile = Tile {
        kd: Plane::Data(kd.clone().into()),
        ks: Plane::Data(ks.into()),
        n: Plane::Data(n.clone().into()),
    };
    let rect = TexelRect {
        x0: 0,
        y0: 0,
        x1: w as u32,
        y1: h as u32,
    };
    let mut levels: Vec<StagedLevel> = (1..=5)
        .map(|level| {
            let lw = (w >> level).max(1);
            let lh = (h >> level).max(1);
            StagedLevel {
                level,
                width: lw,
                kd: vec![0; 4 * lw * lh],
                ks: vec![0; 4 * lw * lh],
                n: vec![0; lw * lh],
            }
        })
        .collect();
    let mut scratch = TileSums::new();
    let total = write_tile_mips(
        &tile,
        rect,
        (w as u32, h as u32),
        true,
        &mut levels,
        &mut scratch,
    );
    assert_eq!(total.count, (w * h) as u64);
    for l in &levels {
        let side = 1_usize << l.level;
        let lh = l.n.len() / l.width;
        for (y, x) in (0..lh).flat_map(|y| (0..l.width).map(move |x| (y, x))) {
            let texels: Vec<usize> = (y * side..((y + 1) * side).min(h))
                .flat_map(|ty| {
                    (x * side..((x + 1) * side).min(w)).map(move |tx| ty * TILE_SIZE + tx)
                })
                .collect();
            let count = texels.len() as u64;
            let sum = texels.iter().map(|&i| u64::from(kd[i][1])).sum::<u64>();
            let got = l.kd[(y * l.width + x) * 4 + 1];
            assert_eq!(
                got,
                mean_code(sum, count, true),
                "level {} ({x}, {y})",
                l.level
            );
            assert_eq!(l.kd[(y * l.width + x) * 4 + 3], u16::MAX, "alpha");
            let n_mean = texels
                .iter()
                .map(|&i| f64::from(decode_n(n[i])))
                .sum::<f64>()
                / count as f64;
            let got = half::f16::from_bits(l.n[y * l.width + x]).to_f64();
            assert!(
                (got - n_mean).abs() <= n_mean * 1e-3 + 1e-3,
                "level {} ({x}, {y}): n {got} vs {n_mean}",
                l.level
            );
        }
    }
}

#[test]
fn top_sums_re_added_over_a_few_tiles_equal_sums_built_whole() {
    // 13 x 9 tiles: odd sides, so blocks at the right and bottom edges are partial.
    let (tx, ty) = (13, 9);
    let sums = |id: usize, k: u64| Sums {
        codes: [1, 2, 3, 4, 5, 6].map(|c| c * 1000 + (id as u64 * 7 + k) % 997),
        n: (id as f64 * 0.37 + k as f64).sin().abs() * 4096.0,
        count: 4096,
    };
    let all = |k: u64| (0..tx * ty).map(|id| (id, sums(id, k))).collect::<Vec<_>>();
    let mut kept = TopSums::new(tx, ty);
    kept.set(&all(0));
    // Some tiles change: the corner, an edge and a scattered few.
    let changed = [0, 12, 50, 51, 64, 116];
    let mut now = all(0);
    for &id in &changed {
        now[id] = (id, sums(id, 5));
    }
    kept.set(&changed.map(|id| now[id]));
    let mut whole = TopSums::new(tx, ty);
    whole.set(&now);
    assert_eq!(kept.grids.len(), 5, "13 x 9, 7 x 5, 4 x 3, 2 x 2, 1 x 1");
    for (k, (a, b)) in kept.grids.iter().zip(&whole.grids).enumerate() {
        assert_eq!(a, b, "grid {k}");
    }
    // The last cell is the sum of every tile.
    let mut total = Sums::default();
    for (_, s) in &now {
        total += *s;
    }
    assert_eq!(kept.grids[4].0[0].codes, total.codes);
    assert_eq!(kept.grids[4].0[0].count, total.count);
}
