// Upscale pass: the interactive frame, drawn at reduced resolution, filtered up to the output size
// with one bilinear tap per pixel — one full-screen draw.

@group(0) @binding(0) var source: texture_2d<f32>;
@group(0) @binding(1) var linear_sampler: sampler;

@fragment
fn fs_main(in: Fullscreen) -> @location(0) vec4<f32> {
    return textureSampleLevel(source, linear_sampler, in.uv, 0.0);
}
