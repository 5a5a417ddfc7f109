// Compute check of the shader's chi against the Rust core: out[i] = chi(MODEL, APPROX, n[i]).

#include "ambient.wgsl"

override MODEL: u32 = 0u;
override APPROX: u32 = 2u;

@group(0) @binding(0) var<storage, read> n_in: array<f32>;
@group(0) @binding(1) var<storage, read_write> chi_out: array<f32>;

@compute @workgroup_size(64)
fn cs_main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i < arrayLength(&n_in) {
        chi_out[i] = chi(MODEL, APPROX, n_in[i]);
    }
}
