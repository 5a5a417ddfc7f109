// The difference compare: |left - right| of two linear renders (the largest of the three
// colour components) as a heatmap, black -> red -> yellow -> white from 0 to `max`. The ramp
// is `render::heat_ramp`'s; a test renders both and compares them.

#include "heat.wgsl"

struct Heat {
    // 1 / max (0 when max is 0): the difference shown white.
    inv_max: f32,
    pad0: f32,
    pad1: f32,
    pad2: f32,
}

@group(0) @binding(0) var left: texture_2d<f32>;
@group(0) @binding(1) var right: texture_2d<f32>;
@group(0) @binding(2) var<uniform> heat: Heat;

// One triangle covering the target.
@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let corner = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_main(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    let xy = vec2<i32>(position.xy);
    let a = textureLoad(left, xy, 0);
    let b = textureLoad(right, xy, 0);
    let d = abs(a.rgb - b.rgb);
    let m = max(d.r, max(d.g, d.b));
    return vec4<f32>(heat_ramp(m * heat.inv_max), max(a.a, b.a));
}
