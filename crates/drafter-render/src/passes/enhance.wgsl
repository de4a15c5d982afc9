// Enhancement pass: the blurred depth of the unsharp mask — a separable Gaussian of the linear
// depth at quarter resolution (fs_blur, horizontal then vertical). The edges are detected where
// they are drawn, in display.wgsl.
// Keep `Enhance` in sync with EnhanceUniforms in gpu_types.rs.

struct Enhance {
    blur: vec4<f32>, // direction, sigma (target texels), radius (target texels)
    far_depth: f32,
    // 1: first direction — read the full-resolution depth every `source_step` texels and replace
    // background pixels by far_depth.
    background_fill: f32,
    source_step: f32,
    pad: f32,
}

@group(0) @binding(0) var<uniform> u: Enhance;
@group(0) @binding(1) var depth_tex: texture_2d<f32>;
@group(0) @binding(2) var id_tex: texture_2d<u32>;

// Linear depth, background pixels at the far depth when filling (first direction).
fn depth_at(p: vec2<i32>) -> f32 {
    let q = clamp(p, vec2<i32>(0), vec2<i32>(textureDimensions(depth_tex)) - 1);
    let d = textureLoad(depth_tex, q, 0).r;
    if u.background_fill > 0.5 && textureLoad(id_tex, q, 0).r == 0u {
        return u.far_depth;
    }
    return d;
}

@fragment
fn fs_blur(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let step = i32(u.source_step);
    let p = vec2<i32>(frag.xy) * step;
    let dir = vec2<i32>(u.blur.xy) * step;
    let sigma = max(u.blur.z, 0.5);
    let radius = i32(u.blur.w);
    var sum = 0.0;
    var weight = 0.0;
    for (var k = -radius; k <= radius; k = k + 1) {
        let w = exp(-0.5 * f32(k * k) / (sigma * sigma));
        sum = sum + w * depth_at(p + dir * k);
        weight = weight + w;
    }
    return vec4<f32>(sum / weight, 0.0, 0.0, 1.0);
}
