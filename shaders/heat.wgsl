// The heatmaps' ramp for t in [0, 1] (0 at no difference, 1 at the scale's top): black, red,
// yellow, white, linear RGB; `render::heat_ramp` is its CPU twin.

fn heat_ramp(t_raw: f32) -> vec3<f32> {
    let t = clamp(t_raw, 0.0, 1.0);
    return vec3<f32>(min(t * 3.0, 1.0), clamp(t * 3.0 - 1.0, 0.0, 1.0), clamp(t * 3.0 - 2.0, 0.0, 1.0));
}
