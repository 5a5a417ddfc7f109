// The preview's bind group: the frame's uniforms, the three maps, their sampler, the
// tangent-space normal map (a flat 1x1 where the material has none) and the per-view table's
// spline coefficients (read only by the per-view views)
// (src/gpu/preview/mod.rs lays out the same bindings).

#include "preview_types.wgsl"

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var kd_map: texture_2d<f32>;
@group(0) @binding(2) var ks_map: texture_2d<f32>;
@group(0) @binding(3) var n_map: texture_2d<f32>;
@group(0) @binding(4) var map_sampler: sampler;
@group(0) @binding(5) var normal_map: texture_2d<f32>;
@group(0) @binding(6) var view_table: texture_2d<f32>;
