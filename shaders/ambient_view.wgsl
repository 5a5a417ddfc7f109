// k_a per view: the ambient coefficient with chi_view(n, phi) at the fragment's own view angle
// instead of its mean over the view, and the view-average error (k_a's relative difference
// from it). chi_view comes from the per-view table (reflectance::view): the not-a-knot cubic
// B-spline through 128 x 128 nodes of ln chi_view, its 130 x 130 coefficients per table read
// from `view_table` (four tables stacked in rows: Phong, Blinn-Phong, Cook-Torrance's chi_1,
// its chi_0; columns run along v, rows along u). `reflectance::view::ka_view` is the CPU twin.

#include "ids.wgsl"
#include "ambient.wgsl"
#include "preview_bindings.wgsl"
#include "view_coords.wgsl"

const VIEW_NODES: i32 = 128;
const VIEW_COEFFICIENTS: i32 = 130;
// The uniform cubic B-spline's four weights at t in [0, 1].
fn view_spline_weights(t: f32) -> vec4<f32> {
    let s = 1.0 - t;
    let t2 = t * t;
    let t3 = t2 * t;
    return vec4<f32>(s * s * s, 3.0 * t3 - 6.0 * t2 + 4.0, -3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0, t3) / 6.0;
}

// chi_view of table `table` at table coordinates `at`.
fn view_table_at(table: i32, at: vec2<f32>) -> f32 {
    let x = clamp(at, vec2<f32>(0.0), vec2<f32>(1.0)) * f32(VIEW_NODES - 1);
    let cell = min(vec2<i32>(floor(x)), vec2<i32>(VIEW_NODES - 2));
    let f = x - vec2<f32>(cell);
    let wu = view_spline_weights(f.x);
    let wv = view_spline_weights(f.y);
    var sum = 0.0;
    for (var a = 0; a < 4; a++) {
        let row = table * VIEW_COEFFICIENTS + cell.x + a;
        let c = vec4<f32>(
            textureLoad(view_table, vec2<i32>(cell.y, row), 0).x,
            textureLoad(view_table, vec2<i32>(cell.y + 1, row), 0).x,
            textureLoad(view_table, vec2<i32>(cell.y + 2, row), 0).x,
            textureLoad(view_table, vec2<i32>(cell.y + 3, row), 0).x,
        );
        sum += wu[a] * dot(c, wv);
    }
    return exp(sum);
}

// (2/pi) k_d + k_s chi_view(n, phi), and + chi_view_0 for Cook-Torrance; k_d, k_s and n
// already sanitized.
fn ambient_ka_view(model: u32, kd: vec3<f32>, ks: vec3<f32>, n_raw: f32, phi: f32) -> vec3<f32> {
    let n = min(n_raw, VIEW_N_MAX);
    let at = view_table_coords(n, clamp(phi, 0.0, VIEW_HALF_PI));
    if model == MODEL_COOK_TORRANCE {
        return TWO_OVER_PI * kd + ks * view_table_at(2, at) + view_table_at(3, at);
    }
    var table = 0;
    if model == MODEL_BLINN {
        table = 1;
    }
    return TWO_OVER_PI * kd + ks * view_table_at(table, at);
}

// The top of the view-average error's heat scale (render::VIEW_ERROR_TOP).
const VIEW_ERROR_TOP: f32 = 1.0;

// The largest over the channels of |live - reference| / reference (render::relative_error):
// 0 where both are 0, the float maximum where only the reference is.
fn relative_error(live: vec3<f32>, reference: vec3<f32>) -> f32 {
    var worst = 0.0;
    for (var i = 0; i < 3; i++) {
        let d = abs(live[i] - reference[i]);
        var e = 0.0;
        if reference[i] > 0.0 {
            e = d / reference[i];
        } else if d > 0.0 {
            e = 3.4028235e38;
        }
        worst = max(worst, e);
    }
    return worst;
}
