// Enhancement pass: separable Gaussian blur of the linear depth (fs_blur, twice), then edges from
// discontinuities of part id, depth and normal plus the depth unsharp mask (fs_edges).
// Keep `Enhance` in sync with EnhanceUniforms in gpu_types.rs.

struct Enhance {
    blur: vec4<f32>, // direction (px), sigma (px), radius (taps)
    far_depth: f32,
    depth_threshold: f32,
    crease_cos: f32,
    line_radius: f32,
    unsharp_strength: f32,
    ortho: f32,
    scene_radius: f32,
    background_fill: f32,
}

@group(0) @binding(0) var<uniform> u: Enhance;
@group(0) @binding(1) var depth_tex: texture_2d<f32>;
@group(0) @binding(2) var id_tex: texture_2d<u32>;
@group(0) @binding(3) var normal_tex: texture_2d<f32>;
@group(0) @binding(4) var blurred_tex: texture_2d<f32>;

@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

fn clamp_xy(p: vec2<i32>) -> vec2<i32> {
    let size = vec2<i32>(textureDimensions(id_tex));
    return clamp(p, vec2<i32>(0), size - 1);
}

fn part_at(p: vec2<i32>) -> u32 {
    return textureLoad(id_tex, clamp_xy(p), 0).r;
}

// Linear depth, with background pixels at the far depth when filling (first blur direction).
fn depth_at(p: vec2<i32>) -> f32 {
    let q = clamp_xy(p);
    let d = textureLoad(depth_tex, q, 0).r;
    if u.background_fill > 0.5 && textureLoad(id_tex, q, 0).r == 0u {
        return u.far_depth;
    }
    return d;
}

@fragment
fn fs_blur(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(frag.xy);
    let dir = vec2<i32>(u.blur.xy);
    let sigma = max(u.blur.z, 0.5);
    let radius = i32(u.blur.w);
    var sum = 0.0;
    var weight = 0.0;
    // Every second tap: the depth is smooth enough between them.
    for (var k = -radius; k <= radius; k = k + 2) {
        let w = exp(-0.5 * f32(k * k) / (sigma * sigma));
        sum = sum + w * depth_at(p + dir * k);
        weight = weight + w;
    }
    return vec4<f32>(sum / weight, 0.0, 0.0, 1.0);
}

// Depth as a quantity that is affine along a plane in screen space: 1/z for a perspective camera, z
// for an orthographic one. Its second difference is zero on planes and large across a jump.
fn affine_depth(d: f32) -> f32 {
    return select(1.0 / max(d, 1e-30), d, u.ortho > 0.5);
}

@fragment
fn fs_edges(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(frag.xy);
    let id = part_at(p);
    let d = textureLoad(depth_tex, clamp_xy(p), 0).r;
    let n = textureLoad(normal_tex, clamp_xy(p), 0).xyz;
    let r = max(i32(round(u.line_radius)), 1);
    let outer = i32(round(u.line_radius * 1.5));
    var outline = 0.0;
    var crease = 0.0;
    let axes = array<vec2<i32>, 4>(vec2<i32>(1, 0), vec2<i32>(-1, 0), vec2<i32>(0, 1), vec2<i32>(0, -1));
    for (var a = 0u; a < 4u; a = a + 1u) {
        for (var k = 1; k <= max(r, outer); k = k + 1) {
            let q = p + axes[a] * k;
            let id_q = part_at(q);
            if id_q == id {
                continue;
            }
            if id == 0u {
                // Background beside the model: the outer half of the heavier outline.
                if k <= r {
                    outline = 1.0;
                }
            } else if id_q == 0u {
                // Model beside the background: the inner half of the outline.
                if k <= outer {
                    outline = 1.0;
                }
            } else if k <= r && d <= textureLoad(depth_tex, clamp_xy(q), 0).r {
                // Border between parts: drawn on the nearer side.
                outline = 1.0;
            }
        }
    }
    if id != 0u {
        // Silhouettes and occluding contours inside a part: a depth jump (second difference of the
        // affine depth) towards a farther neighbour, drawn on the nearer side.
        let g = affine_depth(d);
        for (var a = 0u; a < 2u; a = a + 1u) {
            for (var k = 1; k <= r; k = k + 1) {
                let pa = p + axes[2u * a] * k;
                let pb = p + axes[2u * a + 1u] * k;
                if part_at(pa) != id || part_at(pb) != id {
                    continue;
                }
                let da = textureLoad(depth_tex, clamp_xy(pa), 0).r;
                let db = textureLoad(depth_tex, clamp_xy(pb), 0).r;
                let second = abs(affine_depth(da) + affine_depth(db) - 2.0 * g) / max(abs(g), 1e-30);
                if second > u.depth_threshold && max(da, db) - d > 0.002 * u.scene_radius {
                    outline = 1.0;
                }
            }
        }
        // Creases: the normal turns by more than the crease angle towards the next pixel (right
        // and down only, so the line is one pixel wide per unit of radius).
        for (var a = 0u; a < 4u; a = a + 2u) {
            for (var k = 1; k <= r; k = k + 1) {
                let q = p + axes[a] * k;
                if part_at(q) == id {
                    let m = textureLoad(normal_tex, clamp_xy(q), 0).xyz;
                    if dot(n, m) < u.crease_cos {
                        crease = 1.0;
                    }
                }
            }
        }
    }
    // Unsharp mask of the depth buffer (Luft et al. 2006): ΔD = G∗D − D < 0 where a pixel lies
    // behind its surroundings; darken it in proportion (foreground only).
    var darken = 0.0;
    if id != 0u {
        let delta = textureLoad(blurred_tex, clamp_xy(p), 0).r - d;
        darken = clamp(-delta / u.scene_radius * u.unsharp_strength, 0.0, 0.6);
    }
    return vec4<f32>(outline, crease, darken, 1.0);
}
