//! The fitted exponent per roughness and the conversion-error tables, computed over the
//! paper's box of directions (offline: `cargo run --release --example fit_pbr` writes
//! `table.rs` and `table_height.rs` from here).
//!
//! For a glTF roughness `r` (GGX `alpha = r^2`), the radiance factor of the Cook-Torrance
//! model is `k_d cos t + k_s rho_1 + rho_0` per colour channel (Schlick's `F` split as in
//! [`kapaint_reflectance::cook_torrance`]); a Phong or Blinn-Phong target shades the converted
//! texel as `k_d cos t + k_s c^n` with `c = max(0, R.V)` or `max(0, N.H)`. `k_d` converts
//! unchanged, so the difference at one direction is `k_s (rho_1 - c^n) + rho_0`.
//!
//! * **The fit.** `n` minimises the box average of `|rho_1 + rho_0 - c^n|`: the GGX lobe with
//!   `F = 1` against the target lobe (the L1 distance of the two lobes; L2 would weigh the
//!   peak of a narrow normalised lobe, whose square grows like `1 / alpha^2`, above
//!   everything else).
//! * **The error** of a texel is `avg |k_s (rho_1 - c^n) + rho_0|` divided by the
//!   Cook-Torrance mean `(2/pi) k_d + k_s avg rho_1 + avg rho_0` (the relative mean absolute
//!   difference of the shading over the box), per channel. The numerator depends on `k_s`
//!   and `r` only, so it is tabulated on a grid of both ([`KS_NODES`] values of `k_s`,
//!   dense near the dielectric 0.04).
//!
//! The average uses a product tanh-sinh rule on pieces graded geometrically away from the
//! lobes' common peak (the mirror direction), as the exact integrators do, at a low level:
//! the rule's own integrals of each lobe alone are checked against the exact `chi` values.

use std::f64::consts::PI;

use rayon::prelude::*;

use kapaint_reflectance::ShadingModel;
use kapaint_reflectance::cook_torrance;
use kapaint_reflectance::geometry::golden_section;
use kapaint_reflectance::model::Cosines;
use kapaint_reflectance::quadrature::TanhSinh;

/// Number of `k_s` values of the error tables: `k_s = (i / (KS_NODES - 1))^2`.
pub const KS_NODES: usize = 17;

/// The smallest roughness of the tables; below it the tables' end holds (a mirror there:
/// GGX `alpha < 0.001`, beyond the integrators' range).
pub const ROUGHNESS_MIN: f64 = 1.0 / 32.0;

/// The largest lobe height the fit gives (`k_s = F0 height`): the converted `k_s` never
/// exceeds `F0`, so the conversion adds no energy; the height only lowers the lobe where GGX's
/// sinks below `F0` (the rough end), and the smooth end keeps today's `k_s = F0`.
pub const MAX_HEIGHT: f64 = 1.0;

/// The tanh-sinh level of the box rule the tables are made with.
pub const LEVEL: u32 = 2;

/// The least the height mapping's exponent falls from one row to the next (relative): 2 %
/// a row is 0.5 % an 8-bit roughness level, five steps of the half float that stores `n`,
/// so the export reads every level back. Unconstrained, Phong's fit stalls at roughness 0.48
/// to 0.52 (the height still 1, the exponent still wanting the height-fixed value).
pub const MIN_FALL: f64 = 0.02;

/// Number of clamp factors of the height mapping's error table: the converted `k_s` is
/// `q F0 height` with `q = l / (CLAMP_NODES - 1)` (1 where the energy guard leaves it whole).
pub const CLAMP_NODES: usize = 9;

mod render;
pub use render::{height_error_bytes, render_height_rust, render_rust};

/// `k_s` at error-table node `i`.
pub fn ks_node(i: usize) -> f64 {
    let u = i as f64 / (KS_NODES - 1) as f64;
    u * u
}

/// The targets, in table order.
pub const TARGETS: [ShadingModel; ShadingModel::ALL.len()] = ShadingModel::ALL;

/// The exponent the Cook-Torrance model gives `alpha = r^2` (`2 / alpha^2 - 2`), unclamped.
pub fn ct_n(roughness: f64) -> f64 {
    let a2 = roughness.powi(4);
    (2.0 / a2 - 2.0).max(0.0)
}

/// One node's weight, GGX parts and cosines.
type NodeValues = (f64, [f64; 2], Cosines<f64>);

/// The lobes sampled at the nodes of a box rule fitted to one roughness.
pub struct LobeSamples {
    /// The Cook-Torrance model's painted exponent for the roughness (clamped to `N_MAX`).
    n_painted: f64,
    /// Weights: `sum w f` is the box average of `f`.
    weight: Vec<f64>,
    /// GGX `[rho_1, rho_0]` at the roughness.
    ggx: Vec<[f64; 2]>,
    /// The geometry at each node, where every target evaluates its own lobe.
    cosines: Vec<Cosines<f64>>,
}

impl LobeSamples {
    /// Samples the lobes for `roughness` (clamped to `[ROUGHNESS_MIN, 1]`) with a rule of
    /// `level` (see [`TanhSinh::new`]).
    pub fn new(roughness: f64, level: u32) -> Self {
        let r = roughness.clamp(ROUGHNESS_MIN, 1.0);
        let alpha = r * r;
        let n_ggx = ct_n(r);
        let n_painted = n_ggx.min(f64::from(kapaint_model::texel::N_MAX));
        // The target lobes are about as wide as GGX's (the fit makes them so); half of alpha
        // resolves both.
        let scale = 0.5 * alpha;
        let rule = TanhSinh::new(level);
        let p_breaks = cook_torrance::p_pieces(scale);
        // 2 for g folded onto [0, pi/2], 2/pi^3 for the average.
        let norm = 4.0 / (PI * PI * PI);
        let per_phi: Vec<Vec<NodeValues>> = rule
            .points(&p_breaks)
            .into_par_iter()
            .map(|(p, wp)| {
                let mut out = Vec::new();
                let t_breaks = cook_torrance::t_pieces(scale, p);
                for (t, wt) in rule.points(&t_breaks) {
                    let g_breaks = cook_torrance::g_pieces(scale, p, t.sin());
                    for (g, wg) in rule.points(&g_breaks) {
                        let cosines = Cosines::of_box(t, g, p);
                        let ggx = ShadingModel::CookTorrance.lobe(&cosines, n_ggx);
                        out.push((norm * wp * wt * wg, ggx, cosines));
                    }
                }
                out
            })
            .collect();
        let mut out = Self {
            n_painted,
            weight: Vec::new(),
            ggx: Vec::new(),
            cosines: Vec::new(),
        };
        for (w, ggx, cosines) in per_phi.into_iter().flatten() {
            out.weight.push(w);
            out.ggx.push(ggx);
            out.cosines.push(cosines);
        }
        out
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.weight.len()
    }

    /// Always false for a built rule.
    pub fn is_empty(&self) -> bool {
        self.weight.is_empty()
    }

    /// The box averages `[avg rho_1, avg rho_0]` of GGX at the roughness.
    pub fn ggx_means(&self) -> [f64; 2] {
        self.weight
            .iter()
            .zip(&self.ggx)
            .fold([0.0; 2], |s, (w, g)| [s[0] + w * g[0], s[1] + w * g[1]])
    }

    /// The box average of `max(0, c)^n` for a Phong or Blinn-Phong target: the rule's
    /// `chi(n)`, to check it against the exact integral.
    pub fn target_mean(&self, target: ShadingModel, n: f64) -> f64 {
        (0..self.len())
            .map(|i| self.weight[i] * self.target_at(target, n, i))
            .sum()
    }

    /// The target's `[rho_1, rho_0]` at node `i` for exponent `n` (Cook-Torrance: its painted
    /// exponent, whatever `n`).
    fn target_parts(&self, target: ShadingModel, n: f64, i: usize) -> [f64; 2] {
        let n = if target.is_microfacet() {
            self.n_painted
        } else {
            n
        };
        target.lobe(&self.cosines[i], n)
    }

    /// The target's whole lobe `rho_1 + rho_0` (`F = 1`) at node `i` (as [`Self::target_parts`]).
    fn target_at(&self, target: ShadingModel, n: f64, i: usize) -> f64 {
        let [first, second] = self.target_parts(target, n, i);
        first + second
    }

    /// The L1 distance over the box between the GGX lobe (`F = 1`) and the target's lobe of
    /// exponent `n`.
    pub fn lobe_distance(&self, target: ShadingModel, n: f64) -> f64 {
        self.box_sum(|i| {
            let [g1, g0] = self.ggx[i];
            let [t1, t0] = self.target_parts(target, n, i);
            self.weight[i] * (g1 + g0 - t1 - t0).abs()
        })
    }

    /// `sum f(i)` over the nodes, in fixed chunks summed in order: the result does not depend
    /// on the thread count.
    fn box_sum(&self, f: impl Fn(usize) -> f64 + Sync) -> f64 {
        const CHUNK: usize = 1 << 16;
        let len = self.len();
        let chunks: Vec<f64> = (0..len.div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| (c * CHUNK..((c + 1) * CHUNK).min(len)).map(&f).sum::<f64>())
            .collect();
        chunks.iter().sum()
    }

    /// The exponent in `[0, cap]` (`cap` at most `N_MAX`) that minimises
    /// [`Self::lobe_distance`]: a scan of `u = ln(1 + n)` followed by golden-section search
    /// around the best point. For the Cook-Torrance target, its own painted exponent.
    pub fn fit_n(&self, target: ShadingModel, cap: f64) -> f64 {
        if target.is_microfacet() {
            return self.n_painted;
        }
        minimise_exponent(cap, |n| self.lobe_distance(target, n))
    }

    /// The lobe height `s` in `[0, MAX_HEIGHT]` that minimises the box average of
    /// `|rho_GGX - s c^n|` for the target's lobe of exponent `n` (Phong or Blinn-Phong), and
    /// that distance. Since `|g - s t| = t |g / t - s|`, the unbounded minimum is the weighted
    /// median of `rho_GGX / c^n` with weights `w c^n` (where `c^n > 0`); the distance is convex
    /// in `s`, so the bounded one is that median clamped (found without sorting when at least
    /// half the weight lies at or above the bound).
    pub fn height_for(&self, target: ShadingModel, n: f64) -> (f64, f64) {
        let ratios: Vec<(f64, f64)> = (0..self.len())
            .into_par_iter()
            .filter_map(|i| {
                let t = self.target_at(target, n, i);
                let wt = self.weight[i] * t;
                let [g1, g0] = self.ggx[i];
                (wt > 0.0).then(|| ((g1 + g0) / t, wt))
            })
            .collect();
        let total: f64 = ratios.iter().map(|r| r.1).sum();
        let above: f64 = ratios
            .iter()
            .filter(|r| r.0 >= MAX_HEIGHT)
            .map(|r| r.1)
            .sum();
        let s = if above >= 0.5 * total {
            MAX_HEIGHT
        } else {
            let mut ratios = ratios;
            ratios.par_sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
            let mut seen = 0.0;
            ratios
                .iter()
                .find(|(_, w)| {
                    seen += w;
                    seen >= 0.5 * total
                })
                .map_or(0.0, |(r, _)| *r)
        };
        let distance = self.box_sum(|i| {
            let [g1, g0] = self.ggx[i];
            self.weight[i] * (g1 + g0 - s * self.target_at(target, n, i)).abs()
        });
        (s, distance)
    }

    /// The exponent in `[0, cap]` and the lobe height that together minimise the box L1
    /// distance to the GGX lobe ([`Self::height_for`] at each exponent): a scan of
    /// `u = ln(1 + n)` and golden-section search around its best point, as [`Self::fit_n`].
    pub fn fit_n_and_height(&self, target: ShadingModel, cap: f64) -> (f64, f64) {
        let n = minimise_exponent(cap, |n| self.height_for(target, n).1);
        (n, self.height_for(target, n).0)
    }

    /// The L1 distance between the two lobes each divided by its mean (their shapes).
    pub fn shape_distance(&self, target: ShadingModel, n: f64) -> f64 {
        let chi = self.target_mean(target, n);
        let [m1, m0] = self.ggx_means();
        (0..self.len())
            .map(|i| {
                let [g1, g0] = self.ggx[i];
                self.weight[i] * ((g1 + g0) / (m1 + m0) - self.target_at(target, n, i) / chi).abs()
            })
            .sum()
    }

    /// `[weight, rho_1 - h t_1, rho_0 - h t_0]` at every node for the target's lobe of
    /// exponent `n` and height `h`.
    fn differences(&self, target: ShadingModel, n: f64, h: f64) -> Vec<[f64; 3]> {
        (0..self.len())
            .into_par_iter()
            .map(|i| {
                let [g1, g0] = self.ggx[i];
                let [t1, t0] = self.target_parts(target, n, i);
                [self.weight[i], g1 - h * t1, g0 - h * t0]
            })
            .collect()
    }

    /// The numerator of the conversion error at `k_s`: the box average of
    /// `|k_s (rho_1 - t_1) + (rho_0 - t_0)|` for the target's lobe of exponent `n`.
    pub fn error_at(&self, target: ShadingModel, n: f64, ks: f64) -> f64 {
        self.differences(target, n, 1.0)
            .iter()
            .map(|[w, a, b]| w * (ks * a + b).abs())
            .sum()
    }

    /// [`Self::error_at`] at every `k_s` node.
    pub fn error_table(&self, target: ShadingModel, n: f64) -> [f64; KS_NODES] {
        let diffs = self.differences(target, n, 1.0);
        std::array::from_fn(|k| {
            let ks = ks_node(k);
            diffs.iter().map(|[w, a, b]| w * (ks * a + b).abs()).sum()
        })
    }

    /// The error numerator of a texel of `F0` converted to `k_s` (any height, clamped or not)
    /// for the target's lobe of exponent `n`: the box average of `|F0 rho_1 + rho_0 - k_s c^n|`
    /// (what [`Self::error_table_clamped`] tabulates).
    pub fn error_at_height(&self, target: ShadingModel, n: f64, f0: f64, ks: f64) -> f64 {
        self.box_sum(|i| {
            let [g1, g0] = self.ggx[i];
            let t = self.target_parts(target, n, i)[0];
            self.weight[i] * (f0 * g1 + g0 - ks * t).abs()
        })
    }

    /// The error numerator of the height mapping at every `F0` node `j` and clamp factor `q`
    /// (node `l`): the box average of `|F0 rho_1 + rho_0 - q F0 h c^n|`, the GGX shading
    /// against the target's lobe of exponent `n` at the height the energy guard leaves
    /// (`q = 1` where it leaves `k_s = F0 h` whole).
    pub fn error_table_clamped(
        &self,
        target: ShadingModel,
        n: f64,
        h: f64,
    ) -> [[f64; CLAMP_NODES]; KS_NODES] {
        // Summed in fixed chunks, in order: the result does not depend on the thread count.
        let chunks: Vec<[[f64; CLAMP_NODES]; KS_NODES]> = (0..self.len())
            .collect::<Vec<_>>()
            .par_chunks(1 << 14)
            .map(|chunk| {
                let mut sum = [[0.0; CLAMP_NODES]; KS_NODES];
                for &i in chunk {
                    let [g1, g0] = self.ggx[i];
                    let t = h * self.target_parts(target, n, i)[0];
                    let w = self.weight[i];
                    for (j, row) in sum.iter_mut().enumerate() {
                        let f0 = ks_node(j);
                        let g = f0 * g1 + g0;
                        for (l, cell) in row.iter_mut().enumerate() {
                            *cell += w * (g - clamp_node(l) * f0 * t).abs();
                        }
                    }
                }
                sum
            })
            .collect();
        chunks
            .iter()
            .fold([[0.0; CLAMP_NODES]; KS_NODES], |mut acc, c| {
                for (a, b) in acc.iter_mut().zip(c) {
                    for (x, y) in a.iter_mut().zip(b) {
                        *x += y;
                    }
                }
                acc
            })
    }
}

/// `q` at clamp node `l` of the height mapping's error table.
pub fn clamp_node(l: usize) -> f64 {
    l as f64 / (CLAMP_NODES - 1) as f64
}

/// The exponent in `[0, cap]` (`cap` at most `N_MAX`) that minimises `distance`: a scan of
/// `u = ln(1 + n)` followed by golden-section search around the best point, until the interval
/// is at most 1e-4 wide in `u`.
fn minimise_exponent(cap: f64, distance: impl Fn(f64) -> f64) -> f64 {
    const SCAN: usize = 24;
    let u_max = cap
        .clamp(0.0, f64::from(kapaint_model::texel::N_MAX))
        .ln_1p();
    let f = |u: f64| distance(u.exp_m1());
    let du = u_max / SCAN as f64;
    let best = (0..=SCAN)
        .map(|i| (i, f(i as f64 * du)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(0, |(i, _)| i);
    let (lo, hi) = (
        (best as f64 - 1.0).max(0.0) * du,
        (best as f64 + 1.0).min(SCAN as f64) * du,
    );
    let shrink = 2.0 / (5.0_f64.sqrt() - 1.0);
    let steps = ((hi - lo) / 1e-4).ln() / shrink.ln();
    let (lo, hi) = golden_section(f, (lo, hi), steps.ceil().max(0.0) as usize);
    (0.5 * (lo + hi)).exp_m1()
}

/// One roughness' row of the tables.
#[derive(Clone, Debug)]
pub struct Node {
    /// The roughness.
    pub roughness: f64,
    /// GGX's `[avg rho_1, avg rho_0]`: the Cook-Torrance mean is
    /// `(2/pi) k_d + k_s means[0] + means[1]`.
    pub means: [f64; 2],
    /// The fitted exponent per target ([`TARGETS`] order).
    pub n: [f64; 3],
    /// The error numerator per target at every `k_s` node.
    pub error: [[f64; KS_NODES]; 3],
    /// The lobe distance at the fitted exponent, over the GGX mean, per target.
    pub distance: [f64; 3],
    /// The same without the cap (the unconstrained minimum), per target.
    pub free_distance: [f64; 3],
    /// Phong's and Blinn-Phong's exponent and lobe height fitted together (`k_s = F0 h`).
    pub height_fit: [(f64, f64); 2],
    /// Their lobe distance over the GGX mean.
    pub height_distance: [f64; 2],
    /// Their error numerator at every `F0` node ([`ks_node`]) and clamp factor
    /// ([`CLAMP_NODES`]): the converted `k_s` is `q F0 h`.
    pub height_error: [[[f64; CLAMP_NODES]; KS_NODES]; 2],
}

/// The tables' rows for `roughness` values sorted from smooth to rough, with a rule of
/// `level`. The fitted exponent never grows with roughness: each row's search is capped at the
/// previous row's exponent. Unconstrained, the rough end's minimum is a narrower lobe again
/// (the target's lobe peaks at `k_s`, GGX's rough lobe far below it, so a lobe of small
/// support differs least), which would read roughness backwards and leave no inverse for the
/// export; what the cap costs is in the generator's log and the docs.
pub fn fit_curve(roughness: &[f64], level: u32, mut progress: impl FnMut(&Node)) -> Vec<Node> {
    let mut rows: Vec<Node> = Vec::with_capacity(roughness.len());
    for &r in roughness {
        let samples = LobeSamples::new(r, level);
        let cap = rows
            .last()
            .map_or([f64::from(kapaint_model::texel::N_MAX); 3], |row| row.n);
        let mut n = [0.0; 3];
        let mut error = [[0.0; KS_NODES]; 3];
        let (mut distance, mut free_distance) = ([0.0; 3], [0.0; 3]);
        let means = samples.ggx_means();
        let mean = means[0] + means[1];
        for (k, target) in TARGETS.into_iter().enumerate() {
            let free = samples.fit_n(target, f64::from(kapaint_model::texel::N_MAX));
            n[k] = if free <= cap[k] {
                free
            } else {
                samples.fit_n(target, cap[k])
            };
            error[k] = samples.error_table(target, n[k]);
            distance[k] = samples.lobe_distance(target, n[k]) / mean;
            free_distance[k] = samples.lobe_distance(target, free) / mean;
        }
        let mut height_fit = [(0.0, 0.0); 2];
        let mut height_distance = [0.0; 2];
        let mut height_error = [[[0.0; CLAMP_NODES]; KS_NODES]; 2];
        for (k, target) in [ShadingModel::Phong, ShadingModel::BlinnPhong]
            .into_iter()
            .enumerate()
        {
            // Falling by at least MIN_FALL a row, so a stored exponent tells every 8-bit
            // roughness apart.
            let cap = rows
                .last()
                .map_or(f64::from(kapaint_model::texel::N_MAX), |row| {
                    row.height_fit[k].0 * (1.0 - MIN_FALL)
                });
            let (hn, h) = samples.fit_n_and_height(target, f64::from(kapaint_model::texel::N_MAX));
            let (hn, h) = if hn < cap {
                (hn, h)
            } else {
                samples.fit_n_and_height(target, cap)
            };
            height_fit[k] = (hn, h);
            height_distance[k] = samples.height_for(target, hn).1 / mean;
            height_error[k] = samples.error_table_clamped(target, hn, h);
        }
        let row = Node {
            roughness: r,
            means,
            n,
            error,
            distance,
            free_distance,
            height_fit,
            height_distance,
            height_error,
        };
        progress(&row);
        rows.push(row);
    }
    rows
}

/// The tables' roughness rows: `ROUGHNESS_MIN` to 1 in steps of 1/64.
pub fn table_roughness() -> Vec<f64> {
    (2..=64).map(|i| f64::from(i) / 64.0).collect()
}
