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

// The G-buffer at p, clamped to the last texel `hi` (the targets' size less one).
fn part_at(p: vec2<i32>, hi: vec2<i32>) -> u32 {
    return textureLoad(id_tex, clamp(p, vec2<i32>(0), hi), 0).r;
}

fn depth_at(p: vec2<i32>, hi: vec2<i32>) -> f32 {
    return textureLoad(depth_tex, clamp(p, vec2<i32>(0), hi), 0).r;
}

fn normal_at(p: vec2<i32>, hi: vec2<i32>) -> vec3<f32> {
    return textureLoad(normal_tex, clamp(p, vec2<i32>(0), hi), 0).xyz;
}

// Depth as a quantity that is affine along a plane in screen space: 1/z for a perspective camera,
// z for an orthographic one. Its second difference is zero on planes and large across a jump.
fn affine_depth(d: f32) -> f32 {
    return select(1.0 / max(d, 1e-30), d, u.ortho > 0.5);
}

// The outline test of a model pixel (part `id`, depth `d`) against the neighbour `k` pixels away
// (part `id_q`, depth `d_q`, read only for k <= r): the background within `outer` pixels (the
// heavier outer line), or another part within `r` pixels and farther (drawn on the nearer side).
fn outline_against(id: u32, d: f32, id_q: u32, d_q: f32, k: i32, r: i32, outer: i32) -> bool {
    if id_q == id {
        return false;
    }
    if id_q == 0u {
        return k <= outer;
    }
    return k <= r && d <= d_q;
}

// A depth jump inside the part across p, between the neighbours `a` and `b` at the same distance
// on either side (second difference of the affine depth `g` of p), towards a farther neighbour:
// silhouettes and occluding contours of a part over itself.
fn depth_jump(id: u32, d: f32, g: f32, id_a: u32, id_b: u32, da: f32, db: f32) -> bool {
    if id_a != id || id_b != id {
        return false;
    }
    let second = abs(affine_depth(da) + affine_depth(db) - 2.0 * g) / max(abs(g), 1e-30);
    return second > u.depth_threshold && max(da, db) - d > 0.002 * u.scene_radius;
}

// The image-space edges at pixel p, read in one walk outwards along the four axis directions, each
// neighbour once (a CPU rasteriser pays for every texel read of every pixel):
// - outline: on the background, the model within `r` pixels; on the model, the background within
//   `outer` pixels, a nearer pixel of another part within `r`, or a depth jump (above) within `r`;
// - crease: the normal turns by more than the crease angle within `r` pixels right or down, within
//   the part (right and down only, so the line is one pixel wide per unit of radius).
struct Edges {
    outline: bool,
    crease: bool,
}

fn edges_at(p: vec2<i32>, id: u32, d: f32, hi: vec2<i32>, r: i32, outer: i32) -> Edges {
    var e = Edges(false, false);
    let x = vec2<i32>(1, 0);
    let y = vec2<i32>(0, 1);
    if id == 0u {
        // Only the model within r pixels counts for the background.
        if has(DISPLAY_OUTLINES) {
            for (var k = 1; k <= r && !e.outline; k = k + 1) {
                e.outline = part_at(p + x * k, hi) != 0u || part_at(p - x * k, hi) != 0u
                    || part_at(p + y * k, hi) != 0u || part_at(p - y * k, hi) != 0u;
            }
        }
        return e;
    }
    let g = affine_depth(d);
    var n = vec3<f32>(0.0);
    if has(DISPLAY_CREASES) {
        n = normal_at(p, hi);
    }
    let reach = select(r, max(r, outer), has(DISPLAY_OUTLINES));
    for (var k = 1; k <= reach; k = k + 1) {
        let right = p + x * k;
        let left = p - x * k;
        let down = p + y * k;
        let up = p - y * k;
        let id_r = part_at(right, hi);
        let id_l = part_at(left, hi);
        let id_d = part_at(down, hi);
        let id_u = part_at(up, hi);
        var d_r = 0.0;
        var d_l = 0.0;
        var d_d = 0.0;
        var d_u = 0.0;
        if k <= r && has(DISPLAY_OUTLINES) {
            d_r = depth_at(right, hi);
            d_l = depth_at(left, hi);
            d_d = depth_at(down, hi);
            d_u = depth_at(up, hi);
        }
        if has(DISPLAY_OUTLINES) {
            e.outline = e.outline || outline_against(id, d, id_r, d_r, k, r, outer)
                || outline_against(id, d, id_l, d_l, k, r, outer) || outline_against(id, d, id_d, d_d, k, r, outer)
                || outline_against(id, d, id_u, d_u, k, r, outer);
            if k <= r {
                e.outline = e.outline || depth_jump(id, d, g, id_r, id_l, d_r, d_l)
                    || depth_jump(id, d, g, id_d, id_u, d_d, d_u);
            }
        }
        if k <= r && has(DISPLAY_CREASES) {
            e.crease = e.crease || (id_r == id && dot(n, normal_at(right, hi)) < u.crease_cos)
                || (id_d == id && dot(n, normal_at(down, hi)) < u.crease_cos);
        }
    }
    return e;
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
    let hi = vec2<i32>(textureDimensions(id_tex)) - 1;
    let id = part_at(p, hi);
    var d = 0.0;
    if id != 0u {
        d = depth_at(p, hi);
    }
    let r = max(i32(round(u.line_radius)), 1);
    let outer = i32(round(u.line_radius * 1.5));
    var e = Edges(false, false);
    if has(DISPLAY_OUTLINES) || has(DISPLAY_CREASES) {
        e = edges_at(p, id, d, hi, r, outer);
    }

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
        if e.crease {
            c = mix(c, u.crease_color.rgb, u.crease_color.a);
        }
    }
    if e.outline {
        c = u.line_color.rgb;
    }
    return vec4<f32>(c, 1.0);
}
