// Compute checks of the shading models' shader code against the Rust models (the GPU tests):
// CHECK 0: the lobe, out[2i..2i+2] = specular_lobe(MODEL, N, L, V, sanitize_n(n)) for the
//          point in[10i..10i+10] = (N, L, V, n);
// CHECK 1: the per-view table's coordinates, out[2i..2i+2] = view_table_coords(n, phi) for
//          in[2i..2i+2] = (n, phi).

#include "lobes.wgsl"
#include "view_coords.wgsl"

override MODEL: u32 = 0u;
override CHECK: u32 = 0u;

@group(0) @binding(0) var<storage, read> values: array<f32>;
@group(0) @binding(1) var<storage, read_write> out: array<f32>;

fn vec_at(b: u32) -> vec3<f32> {
    return vec3<f32>(values[b], values[b + 1u], values[b + 2u]);
}

@compute @workgroup_size(64)
fn cs_main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if CHECK == 0u {
        let b = 10u * i;
        if b + 9u < arrayLength(&values) {
            let r = specular_lobe(MODEL, vec_at(b), vec_at(b + 3u), vec_at(b + 6u), sanitize_n(values[b + 9u]));
            out[2u * i] = r.x;
            out[2u * i + 1u] = r.y;
        }
    } else {
        let b = 2u * i;
        if b + 1u < arrayLength(&values) {
            let r = view_table_coords(values[b], values[b + 1u]);
            out[b] = r.x;
            out[b + 1u] = r.y;
        }
    }
}
