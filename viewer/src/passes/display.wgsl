// Display pass: composites the G-buffer colour, the enhancement (outlines, creases, depth
// darkening), the drop shadow and the background, and highlights the selected part.
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
}

const DISPLAY_OUTLINES: u32 = 1u;
const DISPLAY_CREASES: u32 = 2u;
const DISPLAY_UNSHARP: u32 = 4u;
const DISPLAY_SHADOW: u32 = 8u;

@group(0) @binding(0) var<uniform> u: Display;
@group(0) @binding(1) var color_tex: texture_2d<f32>;
@group(0) @binding(2) var id_tex: texture_2d<u32>;
@group(0) @binding(3) var enhance_tex: texture_2d<f32>;
@group(0) @binding(4) var shadow_tex: texture_2d<f32>;

@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_main(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(frag.xy);
    let id = textureLoad(id_tex, p, 0).r;
    let e = textureLoad(enhance_tex, p, 0);
    var c: vec3<f32>;
    if id == 0u {
        c = u.background.rgb;
        if (u.flags & DISPLAY_SHADOW) != 0u {
            let mask = clamp(textureLoad(shadow_tex, p, 0).r, 0.0, 1.0);
            c = mix(c, u.shadow_color.rgb, mask * u.shadow_color.a);
        }
    } else {
        c = textureLoad(color_tex, p, 0).rgb;
        if (u.flags & DISPLAY_UNSHARP) != 0u {
            c = c * (1.0 - e.b);
        }
        if id == u.selected {
            c = mix(c, u.highlight_color.rgb, u.highlight_color.a);
        }
    }
    if (u.flags & DISPLAY_CREASES) != 0u {
        c = mix(c, u.crease_color.rgb, e.g * u.crease_color.a);
    }
    if (u.flags & DISPLAY_OUTLINES) != 0u {
        c = mix(c, u.line_color.rgb, e.r);
    }
    return vec4<f32>(c, 1.0);
}
