// The preview's types: the per-frame uniforms and the vertex stage's input and output.
// `Frame` mirrors `FrameUniforms` in src/gpu/preview/draw_data.rs; a test checks their sizes
// and offsets against naga's layouter.

struct Frame {
    view_proj: mat4x4<f32>,
    // Eye position (object space).
    eye: vec3<f32>,
    // I_a: the hemispherical ambient light's intensity.
    ambient_intensity: f32,
    // Unit direction towards the light.
    light: vec3<f32>,
    // I_l: the light's intensity.
    light_intensity: f32,
    // Uniform values of the maps, used where *_UNIFORM.
    kd: vec3<f32>,
    n: f32,
    ks: vec3<f32>,
    pad: f32,
}

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    // MikkTSpace tangent (xyz) and the bitangent's sign (w); zero without UVs.
    @location(3) tangent: vec4<f32>,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) tangent: vec4<f32>,
}
