//! Per-channel statistics of the maps (for `kapaint info` and the editor's status).

use rayon::prelude::*;

use super::maps::MaterialMaps;
use super::texel::{decode_n, decode_unorm};
use super::tile::{Plane, TILE_SIZE};

/// Min, mean and max of one channel component over the map.
#[derive(Clone, Debug, PartialEq)]
pub struct ChannelStat {
    /// `kd.r`, `kd.g`, `kd.b`, `ks.r`, `ks.g`, `ks.b` or `n`.
    pub label: &'static str,
    /// Smallest value.
    pub min: f64,
    /// Mean value.
    pub mean: f64,
    /// Largest value.
    pub max: f64,
}

const LABELS: [&str; 7] = ["kd.r", "kd.g", "kd.b", "ks.r", "ks.g", "ks.b", "n"];

#[derive(Clone, Copy)]
struct Acc {
    min: [f64; 7],
    max: [f64; 7],
    sum: [f64; 7],
}

impl Acc {
    fn empty() -> Self {
        Self {
            min: [f64::INFINITY; 7],
            max: [f64::NEG_INFINITY; 7],
            sum: [0.0; 7],
        }
    }

    fn add(&mut self, c: usize, v: f64, count: f64) {
        self.min[c] = self.min[c].min(v);
        self.max[c] = self.max[c].max(v);
        self.sum[c] += v * count;
    }

    fn merge(mut self, o: Self) -> Self {
        for c in 0..7 {
            self.min[c] = self.min[c].min(o.min[c]);
            self.max[c] = self.max[c].max(o.max[c]);
            self.sum[c] += o.sum[c];
        }
        self
    }
}

fn plane_rgb(acc: &mut Acc, base: usize, plane: &Plane<[u16; 3]>, cols: usize, rows: usize) {
    match plane {
        Plane::Uniform(v) => {
            for (k, &c) in v.iter().enumerate() {
                acc.add(base + k, f64::from(decode_unorm(c)), (cols * rows) as f64);
            }
        }
        Plane::Data(d) => {
            for y in 0..rows {
                for v in &d[y * TILE_SIZE..y * TILE_SIZE + cols] {
                    for (k, &c) in v.iter().enumerate() {
                        acc.add(base + k, f64::from(decode_unorm(c)), 1.0);
                    }
                }
            }
        }
    }
}

/// Statistics of every channel component, in the order `kd.r .. ks.b, n`.
pub fn channel_stats(maps: &MaterialMaps) -> Vec<ChannelStat> {
    let acc = (0..maps.tile_count())
        .into_par_iter()
        .map(|id| {
            let crate::maps::TexelRect { x0, y0, x1, y1 } = maps.tile_rect(id);
            let (cols, rows) = ((x1 - x0) as usize, (y1 - y0) as usize);
            let tile = maps.tile(id);
            let mut acc = Acc::empty();
            plane_rgb(&mut acc, 0, &tile.kd, cols, rows);
            plane_rgb(&mut acc, 3, &tile.ks, cols, rows);
            match &tile.n {
                Plane::Uniform(v) => acc.add(6, f64::from(decode_n(*v)), (cols * rows) as f64),
                Plane::Data(d) => {
                    for y in 0..rows {
                        for &v in &d[y * TILE_SIZE..y * TILE_SIZE + cols] {
                            acc.add(6, f64::from(decode_n(v)), 1.0);
                        }
                    }
                }
            }
            acc
        })
        .reduce(Acc::empty, Acc::merge);
    let count = maps.texel_count() as f64;
    (0..7)
        .map(|c| ChannelStat {
            label: LABELS[c],
            min: acc.min[c],
            mean: acc.sum[c] / count,
            max: acc.max[c],
        })
        .collect()
}
