// The full-screen triangle every image pass draws (`passes::fullscreen_pipeline`): prepended to
// display.wgsl, enhance.wgsl, shadow.wgsl and upscale.wgsl by `passes::shader_source`, so it is
// written once.

// Corner i of a triangle covering the viewport, in [0, 2]²: (0,0), (2,0), (0,2).
fn fullscreen_corner(i: u32) -> vec2<f32> {
    return vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
}

// The position, and the texture coordinate of the viewport's point (clip y up, texture v down); a
// fragment shader reads what it needs of it.
struct Fullscreen {
    @builtin(position) position: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> Fullscreen {
    let corner = fullscreen_corner(i);
    var out: Fullscreen;
    out.position = vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0);
    out.uv = vec2<f32>(corner.x, 1.0 - corner.y);
    return out;
}
