// Upscale pass: the interactive frame, drawn at reduced resolution, filtered up to the output size
// with one bilinear tap per pixel — one full-screen draw.

@group(0) @binding(0) var source: texture_2d<f32>;
@group(0) @binding(1) var linear_sampler: sampler;

struct Varyings {
    @builtin(position) position: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> Varyings {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    var out: Varyings;
    out.position = vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
    // Clip y up, texture v down.
    out.uv = vec2<f32>(uv.x, 1.0 - uv.y);
    return out;
}

@fragment
fn fs_main(in: Varyings) -> @location(0) vec4<f32> {
    return textureSampleLevel(source, linear_sampler, in.uv, 0.0);
}
