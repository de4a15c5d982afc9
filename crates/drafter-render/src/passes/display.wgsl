// Display pass: detects image-space edges in the G-buffer (part id, depth and normal
// discontinuities), applies the depth unsharp mask, composites the drop shadow and the background,
// and highlights the selected part — one full-screen draw.
// Keep `Display` in sync with DisplayUniforms in gpu_types.rs.

struct Display {
    background: vec4<f32>,
    shadow_color: vec4<f32>, // a: opacity
    line_color: vec4<f32>,
    crease_color: vec4<f32>, // a: opacity
    highlight_color: vec4<f32>, // a: strength
    selected: u32,
    flags: u32,
    pad0: u32,
    pad1: u32,
    depth_threshold: f32,
    crease_cos: f32,
    line_radius: f32,
    unsharp_strength: f32,
    ortho: f32,
    scene_radius: f32,
    pad2: f32,
    pad3: f32,
}

const DISPLAY_OUTLINES: u32 = 1u;
const DISPLAY_CREASES: u32 = 2u;
const DISPLAY_UNSHARP: u32 = 4u;
const DISPLAY_SHADOW: u32 = 8u;

// The flags this pipeline can apply (a pipeline constant, display.rs): the code of the others is
// compiled out, which a CPU rasteriser needs (it runs both sides of every branch).
override FLAGS: u32 = 15u;

fn has(flag: u32) -> bool {
    return (FLAGS & flag) != 0u && (u.flags & flag) != 0u;
}

@group(0) @binding(0) var<uniform> u: Display;
@group(0) @binding(1) var color_tex: texture_2d<f32>;
@group(0) @binding(2) var id_tex: texture_2d<u32>;
@group(0) @binding(3) var normal_tex: texture_2d<f32>;
@group(0) @binding(4) var depth_tex: texture_2d<f32>;
@group(0) @binding(5) var blurred_tex: texture_2d<f32>;
@group(0) @binding(6) var shadow_tex: texture_2d<f32>;
@group(0) @binding(7) var linear_sampler: sampler;

fn clamp_xy(p: vec2<i32>) -> vec2<i32> {
    return clamp(p, vec2<i32>(0), vec2<i32>(textureDimensions(id_tex)) - 1);
}

fn part_at(p: vec2<i32>) -> u32 {
    return textureLoad(id_tex, clamp_xy(p), 0).r;
}

fn depth_at(p: vec2<i32>) -> f32 {
    return textureLoad(depth_tex, clamp_xy(p), 0).r;
}

// Depth as a quantity that is affine along a plane in screen space: 1/z for a perspective camera,
// z for an orthographic one. Its second difference is zero on planes and large across a jump.
fn affine_depth(d: f32) -> f32 {
    return select(1.0 / max(d, 1e-30), d, u.ortho > 0.5);
}

// Outline test towards `dir`: a different part within `r` pixels (drawn on the nearer side), or the
// background within `outer` pixels of the model / the model within `r` pixels of the background
// (both sides: the heavier outer line).
fn outline_towards(p: vec2<i32>, id: u32, d: f32, dir: vec2<i32>, r: i32, outer: i32) -> bool {
    for (var k = 1; k <= max(r, outer); k = k + 1) {
        let q = p + dir * k;
        let id_q = part_at(q);
        if id_q == id {
            continue;
        }
        if id == 0u {
            if k <= r {
                return true;
            }
        } else if id_q == 0u {
            if k <= outer {
                return true;
            }
        } else if k <= r && d <= depth_at(q) {
            return true;
        }
    }
    return false;
}

// A depth jump inside the part along `dir` (second difference of the affine depth), towards a
// farther neighbour: silhouettes and occluding contours of a part over itself.
fn depth_jump_along(p: vec2<i32>, id: u32, d: f32, dir: vec2<i32>, r: i32) -> bool {
    let g = affine_depth(d);
    for (var k = 1; k <= r; k = k + 1) {
        let pa = p + dir * k;
        let pb = p - dir * k;
        if part_at(pa) != id || part_at(pb) != id {
            continue;
        }
        let da = depth_at(pa);
        let db = depth_at(pb);
        let second = abs(affine_depth(da) + affine_depth(db) - 2.0 * g) / max(abs(g), 1e-30);
        if second > u.depth_threshold && max(da, db) - d > 0.002 * u.scene_radius {
            return true;
        }
    }
    return false;
}

// The normal turns by more than the crease angle towards `dir` within the part.
fn crease_towards(p: vec2<i32>, id: u32, n: vec3<f32>, dir: vec2<i32>, r: i32) -> bool {
    for (var k = 1; k <= r; k = k + 1) {
        let q = p + dir * k;
        if part_at(q) == id && dot(n, textureLoad(normal_tex, clamp_xy(q), 0).xyz) < u.crease_cos {
            return true;
        }
    }
    return false;
}

// The blurred depth at full-resolution pixel p: bilinear over the quarter-resolution texels
// (R32Float is not filterable everywhere).
fn blurred_at(p: vec2<i32>) -> f32 {
    let size = vec2<i32>(textureDimensions(blurred_tex));
    let scale = vec2<f32>(size) / vec2<f32>(textureDimensions(id_tex));
    let x = (vec2<f32>(p) + 0.5) * scale - 0.5;
    let base = vec2<i32>(floor(x));
    let w = x - floor(x);
    let hi = size - 1;
    let a = textureLoad(blurred_tex, clamp(base, vec2<i32>(0), hi), 0).r;
    let b = textureLoad(blurred_tex, clamp(base + vec2<i32>(1, 0), vec2<i32>(0), hi), 0).r;
    let c = textureLoad(blurred_tex, clamp(base + vec2<i32>(0, 1), vec2<i32>(0), hi), 0).r;
    let e = textureLoad(blurred_tex, clamp(base + vec2<i32>(1, 1), vec2<i32>(0), hi), 0).r;
    return mix(mix(a, b, w.x), mix(c, e, w.x), w.y);
}

@fragment
fn fs_main(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(frag.xy);
    let id = part_at(p);
    let d = depth_at(p);
    let r = max(i32(round(u.line_radius)), 1);
    let outer = i32(round(u.line_radius * 1.5));
    let x = vec2<i32>(1, 0);
    let y = vec2<i32>(0, 1);

    var c: vec3<f32>;
    if id == 0u {
        c = u.background.rgb;
        if has(DISPLAY_SHADOW) {
            // Four bilinear taps half a mask texel apart: a 3×3 tent over the half-resolution mask.
            let uv = frag.xy / vec2<f32>(textureDimensions(id_tex));
            let o = 0.5 / vec2<f32>(textureDimensions(shadow_tex));
            let sum = textureSampleLevel(shadow_tex, linear_sampler, uv + vec2<f32>(-o.x, -o.y), 0.0).r
                + textureSampleLevel(shadow_tex, linear_sampler, uv + vec2<f32>(o.x, -o.y), 0.0).r
                + textureSampleLevel(shadow_tex, linear_sampler, uv + vec2<f32>(-o.x, o.y), 0.0).r
                + textureSampleLevel(shadow_tex, linear_sampler, uv + vec2<f32>(o.x, o.y), 0.0).r;
            let mask = clamp(0.25 * sum, 0.0, 1.0);
            c = mix(c, u.shadow_color.rgb, mask * u.shadow_color.a);
        }
    } else {
        c = textureLoad(color_tex, p, 0).rgb;
        if has(DISPLAY_UNSHARP) {
            // Unsharp mask of the depth buffer (Luft et al. 2006): ΔD = G∗D − D < 0 where a pixel
            // lies behind its surroundings; darken it in proportion.
            let delta = blurred_at(p) - d;
            c = c * (1.0 - clamp(-delta / u.scene_radius * u.unsharp_strength, 0.0, 0.6));
        }
        if id == u.selected {
            c = mix(c, u.highlight_color.rgb, u.highlight_color.a);
        }
        if has(DISPLAY_CREASES) {
            // Right and down only, so the line is one pixel wide per unit of radius.
            let n = textureLoad(normal_tex, p, 0).xyz;
            if crease_towards(p, id, n, x, r) || crease_towards(p, id, n, y, r) {
                c = mix(c, u.crease_color.rgb, u.crease_color.a);
            }
        }
    }
    if has(DISPLAY_OUTLINES) {
        var outline = outline_towards(p, id, d, x, r, outer) || outline_towards(p, id, d, -x, r, outer)
            || outline_towards(p, id, d, y, r, outer) || outline_towards(p, id, d, -y, r, outer);
        if id != 0u && !outline {
            outline = depth_jump_along(p, id, d, x, r) || depth_jump_along(p, id, d, y, r);
        }
        if outline {
            c = u.line_color.rgb;
        }
    }
    return vec4<f32>(c, 1.0);
}
