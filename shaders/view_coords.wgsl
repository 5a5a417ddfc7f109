// The per-view table's coordinates: where (n, phi) falls in the table, in [0, 1]^2, the twin
// of `reflectance::view::table_coords` (one generic Rust source for f64 and f32; the GPU tests
// check this against it at 10^4 points).

const VIEW_N_MAX: f32 = 16384.0;
const VIEW_GRAZE: f32 = 256.0;
const VIEW_HALF_PI: f32 = 1.5707964f;

fn view_table_coords(n: f32, phi: f32) -> vec2<f32> {
    let width = sqrt(1.0 + n);
    let graze = sqrt(width * width + VIEW_GRAZE * VIEW_GRAZE);
    let u = log2(1.0 + n) / log2(1.0 + VIEW_N_MAX);
    let head_on = log(1.0 + width * phi) / log(1.0 + width * VIEW_HALF_PI);
    let grazing = log(1.0 + graze * (VIEW_HALF_PI - phi)) / log(1.0 + graze * VIEW_HALF_PI);
    return vec2<f32>(u, 0.5 + 0.5 * (head_on - grazing));
}

