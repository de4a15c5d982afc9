// G-buffer pass: rasterises every mesh once (instanced) and shades it in the style of its part.
// Outputs colour, view-space normal, linear view depth and part id + 1 (0 = background).
// Frame and Instance are in shared.wgsl. Keep the structs in sync with gpu_types.rs; style numbers with Style::index in style.rs; the
// lookup bindings with LOOKUP_BINDINGS in gbuffer.rs. Lookups: baked textures where the file has
// them (flags in `lookups`), the procedural formulas otherwise (gbuffer.rs, "Lookup textures").

struct Part {
    projector_row: vec4<f32>,
    axis0: vec4<f32>,
    axis1: vec4<f32>,
    axis2: vec4<f32>,
    gradient: vec4<f32>, // q, f, p, transfer curve index
    style_hint: u32,
    flags: u32, // PART_SELECTED | PART_REFERENCE (gpu_types.rs)
    flat: f32,  // a flat grey in [0, 1], or negative: shaded
    pad0: u32,
}

const PART_SELECTED: u32 = 1u;
const PART_REFERENCE: u32 = 2u;
// The editor's highlights: the selection in a saturated blue (away from the warm and grey tones
// of the styles), its reference part in a lighter blue.
const SELECTED_TINT: vec4<f32> = vec4<f32>(0.1, 0.35, 1.0, 0.5);
const REFERENCE_TINT: vec4<f32> = vec4<f32>(0.55, 0.8, 1.0, 0.6);

struct Lookups {
    flags: u32,
    cel_row_v: f32,
    cel_min_level: f32,
    cel_diffuse_max: f32,
    hatch: vec4<f32>, // tile side (target px), contrast c
    map_light: vec4<f32>,
    map_across: vec4<f32>,
    metal: vec4<f32>, // stripe scale s
}

struct Material {
    base_color: vec4<f32>,
    metallic: f32,
    roughness: f32,
    pad0: f32,
    pad1: f32,
}

const STYLE_PHONG: u32 = 0u;
const STYLE_GRADIENT: u32 = 1u;
const STYLE_CEL: u32 = 2u;
const STYLE_GOOCH: u32 = 3u;
const STYLE_GOOCHEL: u32 = 4u;
const STYLE_METAL: u32 = 5u;
const STYLE_HATCH: u32 = 6u;
const NO_STYLE: u32 = 0xffffffffu;

const FLAG_CEL_SPECULAR: u32 = 1u;
const FLAG_SPLASH_BACK: u32 = 2u;

const LOOKUP_CEL: u32 = 1u;
const LOOKUP_COOL_TO_WARM: u32 = 2u;
const LOOKUP_HATCH: u32 = 4u;
const LOOKUP_METAL: u32 = 8u;
const LOOKUP_CEL_SPECULAR: u32 = 16u;
const LOOKUP_COOL_TO_WARM_FACTORED: u32 = 32u;
const LOOKUP_COOL_TO_WARM_SPLASH: u32 = 64u;
const LOOKUP_COOL_TO_WARM_SPHERE: u32 = 128u;
const LOOKUP_METAL_SPHERE: u32 = 256u;

const PI: f32 = 3.14159265358979;

// The styles this pipeline can draw, bit `Style::index` each (a pipeline constant, gbuffer.rs
// "Specialised pipelines"): the others' code is compiled out. With one bit set, that style is drawn
// whatever the frame and part say.
override STYLES: u32 = 0x7fu;

fn may_draw(style: u32) -> bool {
    return (STYLES & (1u << style)) != 0u;
}

@group(0) @binding(0) var<uniform> frame: Frame;
// The scene's tables (table.rs); the instances come as vertex attributes (InstanceIn, shared.wgsl).
@group(0) @binding(1) var label_table: texture_2d<u32>;
@group(0) @binding(2) var part_table: texture_2d<u32>;
@group(0) @binding(3) var material_table: texture_2d<u32>;

// The part of label k of the scene (4 labels a texel).
fn part_of_label(k: u32) -> u32 {
    return textureLoad(label_table, table_coord(k / 4u), 0)[k % 4u];
}

// Part i: 6 texels.
fn part_at(i: u32) -> Part {
    let t = i * 6u;
    var part: Part;
    part.projector_row = bitcast<vec4<f32>>(textureLoad(part_table, table_coord(t), 0));
    part.axis0 = bitcast<vec4<f32>>(textureLoad(part_table, table_coord(t + 1u), 0));
    part.axis1 = bitcast<vec4<f32>>(textureLoad(part_table, table_coord(t + 2u), 0));
    part.axis2 = bitcast<vec4<f32>>(textureLoad(part_table, table_coord(t + 3u), 0));
    part.gradient = bitcast<vec4<f32>>(textureLoad(part_table, table_coord(t + 4u), 0));
    let rest = textureLoad(part_table, table_coord(t + 5u), 0);
    part.style_hint = rest.x;
    part.flags = rest.y;
    part.flat = bitcast<f32>(rest.z);
    part.pad0 = rest.w;
    return part;
}

// Material i: 2 texels.
fn material_at(i: u32) -> Material {
    var material: Material;
    material.base_color = bitcast<vec4<f32>>(textureLoad(material_table, table_coord(i * 2u), 0));
    let rest = bitcast<vec4<f32>>(textureLoad(material_table, table_coord(i * 2u + 1u), 0));
    material.metallic = rest.x;
    material.roughness = rest.y;
    material.pad0 = rest.z;
    material.pad1 = rest.w;
    return material;
}
@group(0) @binding(4) var<uniform> lookups: Lookups;
@group(0) @binding(5) var gamma_atlas: texture_2d<f32>;
@group(0) @binding(6) var cel_atlas: texture_2d<f32>;
@group(0) @binding(7) var cool_to_warm: texture_2d<f32>;
@group(0) @binding(8) var hatching: texture_2d<f32>;
@group(0) @binding(9) var metal_bands: texture_2d<f32>;
@group(0) @binding(10) var metal_highlights: texture_2d<f32>;
@group(0) @binding(11) var clamp_sampler: sampler;
@group(0) @binding(12) var repeat_sampler: sampler;

struct VertexIn {
    @location(0) position_in_object: vec3<f32>,
    @location(1) normal_in_object: vec3<f32>,
    @location(2) label: u32,
    @location(3) material: u32,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) position_in_render: vec3<f32>,
    @location(1) normal_in_render: vec3<f32>,
    @location(2) @interpolate(flat) part: u32,
    @location(3) @interpolate(flat) material: u32,
    @location(4) @interpolate(flat) mirrored: u32,
}

@vertex
fn vs_main(v: VertexIn, instance: InstanceIn) -> VertexOut {
    let inst = instance_from(instance);
    let position = inst.render_from_object * vec4<f32>(v.position_in_object, 1.0);
    let normal_from_object = mat3x3<f32>(inst.normal_col0.xyz, inst.normal_col1.xyz, inst.normal_col2.xyz);
    let label = min(v.label, max(inst.label_count, 1u) - 1u);
    var out: VertexOut;
    out.clip = frame.clip_from_render * position;
    out.position_in_render = position.xyz;
    out.normal_in_render = normal_from_object * v.normal_in_object;
    out.part = part_of_label(inst.label_base + label);
    out.material = v.material;
    out.mirrored = inst.mirrored;
    return out;
}

struct GBufferOut {
    @location(0) color: vec4<f32>,
    @location(1) normal: vec4<f32>,
    @location(2) depth: f32,
    @location(3) part: u32,
}

// ω(i, q, f, p) of Lux et al. 2013, Listing 1, exactly as drafter-core's `gradient::omega`:
// the band and the position inside it both come from one product t = i^p · q.
fn omega(i_in: f32, q_in: f32, f_in: f32, p_in: f32) -> f32 {
    let i = clamp(i_in, 0.0, 1.0);
    let q = max(q_in, 1.0);
    let f = clamp(f_in, 0.0, 1.0);
    let p = max(p_in, 0.01);
    let r = 0.5 / (q + 1.0);
    let ip = select(pow(i, p), 0.0, i <= 0.0);
    let t = ip * q;
    let band = floor(t);
    let iq = band / q + r;
    let within = t - band;
    var mf = 0.0;
    if f < 1.0 && within >= f {
        mf = (within - f) / (1.0 - f);
    }
    return (iq - r) * (1.0 - mf) + (iq + r) * mf;
}

fn has(flag: u32) -> bool {
    return (lookups.flags & flag) != 0u;
}

// A table row read at x ∈ [0, 1]: texel k holds the value at x = k / (w − 1), so
// u = (0.5 + (w − 1)·x) / w; linear, clamped (the cel atlas).
fn table_row(atlas: texture_2d<f32>, x: f32, v: f32) -> f32 {
    let w = f32(textureDimensions(atlas).x);
    let u = (0.5 + (w - 1.0) * clamp(x, 0.0, 1.0)) / w;
    return textureSampleLevel(atlas, clamp_sampler, vec2<f32>(u, v), 0.0).r;
}

// γ(p): row `row` of the γ atlas (baked or procedural), linearly interpolated (texel k holds
// γ(k / (w − 1))); read with textureLoad, as the procedural atlas is 32-bit float.
fn transfer(p: f32, row: u32) -> f32 {
    let w = textureDimensions(gamma_atlas).x;
    let x = clamp(p, 0.0, 1.0) * f32(w - 1u);
    let k = min(u32(floor(x)), w - 1u);
    let next = min(k + 1u, w - 1u);
    let a = textureLoad(gamma_atlas, vec2<u32>(k, row), 0).r;
    let b = textureLoad(gamma_atlas, vec2<u32>(next, row), 0).r;
    return mix(a, b, x - f32(k));
}

// The baked cel row at x.
fn cel_table(x: f32) -> f32 {
    return table_row(cel_atlas, x, lookups.cel_row_v);
}

// Texture coordinate of an eye-space normal in an environment map (drafter-textures' envmap).
fn env_uv(n_in: vec3<f32>, sphere: bool) -> vec2<f32> {
    let n = normalize(n_in);
    if sphere {
        return vec2<f32>(0.5 + 0.5 * n.x, 0.5 - 0.5 * n.y);
    }
    var p = n.xy / (abs(n.x) + abs(n.y) + abs(n.z));
    if n.z < 0.0 {
        p = (1.0 - abs(p.yx)) * select(vec2<f32>(-1.0), vec2<f32>(1.0), p >= vec2<f32>(0.0));
    }
    return vec2<f32>(0.5 + 0.5 * p.x, 0.5 - 0.5 * p.y);
}

// The baked cool-to-warm map at n·l = c: read at the normal c·l_map + √(1 − c²)·a, which has that
// cosine with the map's light (the map depends on nothing else).
fn cool_to_warm_at(c_in: f32, base: vec3<f32>) -> vec3<f32> {
    let c = clamp(c_in, -1.0, 1.0);
    let n = c * lookups.map_light.xyz + sqrt(max(1.0 - c * c, 0.0)) * lookups.map_across.xyz;
    let texel = textureSampleLevel(cool_to_warm, clamp_sampler, env_uv(n, has(LOOKUP_COOL_TO_WARM_SPHERE)), 0.0);
    if has(LOOKUP_COOL_TO_WARM_FACTORED) {
        return clamp(texel.rgb + texel.a * base, vec3<f32>(0.0), vec3<f32>(1.0));
    }
    return texel.rgb;
}

// The procedural metal table at x (entry k at x = k / n, periodic): texel centres are half a texel
// further.
fn metal_table(x: f32) -> f32 {
    let n = f32(textureDimensions(metal_bands).x);
    return textureSampleLevel(metal_bands, repeat_sampler, vec2<f32>(x + 0.5 / n, 0.5), 0.0).r;
}

// Gooch et al. 1998 cool and warm tones: k_cool = (0, 0, b) + α k_d, k_warm = (y, y, 0) + β k_d with
// b = y = 0.4, α = 0.2, β = 0.6.
fn gooch_tones(base: vec3<f32>, t: f32) -> vec3<f32> {
    let cool = vec3<f32>(0.0, 0.0, 0.4) + 0.2 * base;
    let warm = vec3<f32>(0.4, 0.4, 0.0) + 0.6 * base;
    return mix(cool, warm, t);
}

fn cel_level(x: f32) -> f32 {
    let steps = f32(clamp(frame.cel_steps, 2u, 4u));
    let k = min(floor(clamp(x, 0.0, 1.0) * steps), steps - 1.0);
    return k / (steps - 1.0);
}

struct Surface {
    position_in_render: vec3<f32>,
    n: vec3<f32>, // view space, towards the viewer
    l: vec3<f32>, // view space, towards the light
    v: vec3<f32>, // view space, towards the viewer
    base: vec3<f32>,
    roughness: f32,
    frag: vec2<f32>,
}

fn shade_phong(s: Surface) -> vec3<f32> {
    let h = normalize(s.l + s.v);
    let diffuse = max(dot(s.n, s.l), 0.0);
    let shininess = mix(64.0, 8.0, clamp(s.roughness, 0.0, 1.0));
    let specular = 0.35 * pow(max(dot(s.n, h), 0.0), shininess) * step(0.0, dot(s.n, s.l));
    return s.base * (0.22 + 0.78 * diffuse) + vec3<f32>(specular);
}

// Lux et al.: p from the part's projector, i = γ(p), i' = ω(i, q, f, p), shown as a grey value
// slightly tinted by the material so that parts stay apart.
fn shade_gradient(s: Surface, part: Part) -> vec3<f32> {
    let p = dot(part.projector_row, vec4<f32>(s.position_in_render, 1.0));
    let i = transfer(p, u32(part.gradient.w));
    let w = omega(i, part.gradient.x, part.gradient.y, part.gradient.z);
    let tint = mix(vec3<f32>(1.0), s.base, 0.3);
    return tint * mix(0.18, 1.0, w);
}

fn shade_cel(s: Surface) -> vec3<f32> {
    if has(LOOKUP_CEL) {
        // The baked row: diffuse steps scale the base colour relative to the brightest one; the
        // specular band above it goes towards white.
        let value = cel_table(max(dot(s.n, s.l), 0.0));
        let top = lookups.cel_diffuse_max;
        var c = s.base * (min(value, top) / top);
        if has(LOOKUP_CEL_SPECULAR) {
            c = mix(c, vec3<f32>(1.0), 0.8 * clamp((value - top) / max(1.0 - top, 1e-3), 0.0, 1.0));
        }
        return c;
    }
    let level = cel_level(max(dot(s.n, s.l), 0.0));
    var c = s.base * mix(0.35, 1.0, level);
    if (frame.flags & FLAG_CEL_SPECULAR) != 0u {
        let h = normalize(s.l + s.v);
        if pow(max(dot(s.n, h), 0.0), 40.0) > 0.5 {
            c = mix(c, vec3<f32>(1.0), 0.8);
        }
    }
    return c;
}

fn shade_gooch(s: Surface) -> vec3<f32> {
    let nl = dot(s.n, s.l);
    let splash = (frame.flags & FLAG_SPLASH_BACK) != 0u;
    let alpha = frame.style_params.x;
    let beta = frame.style_params.y;
    var c: vec3<f32>;
    if has(LOOKUP_COOL_TO_WARM) {
        c = cool_to_warm_at(nl, s.base);
        if splash && !has(LOOKUP_COOL_TO_WARM_SPLASH) {
            // Gooch et al. 1999, §3.2, as drafter-textures bakes it: |α cos θ + (1 − α)|^β.
            c = c * pow(abs(alpha * nl + (1.0 - alpha)), beta);
        }
    } else {
        c = gooch_tones(s.base, 0.5 * (1.0 + nl));
        if splash {
            // Gooch et al. 1999, §3.2: (α|cos θ| + (1 − α))^β darkens the terminator and lets
            // light splash back opposite the key light.
            c = c * pow(alpha * abs(nl) + (1.0 - alpha), beta);
        }
    }
    let h = normalize(s.l + s.v);
    let highlight = pow(max(dot(s.n, h), 0.0), 48.0) * step(0.0, nl);
    return min(c + vec3<f32>(0.5 * highlight), vec3<f32>(1.0));
}

// ten Bosch's Goochel: the cel steps of the full-range (1 + n·l)/2 as the cool-to-warm blend.
fn shade_goochel(s: Surface) -> vec3<f32> {
    let x = 0.5 * (1.0 + dot(s.n, s.l));
    var t: f32;
    if has(LOOKUP_CEL) {
        let low = lookups.cel_min_level;
        let top = lookups.cel_diffuse_max;
        t = clamp((min(cel_table(x), top) - low) / max(top - low, 1e-3), 0.0, 1.0);
    } else {
        t = cel_level(x);
    }
    if has(LOOKUP_COOL_TO_WARM) {
        return cool_to_warm_at(2.0 * t - 1.0, s.base);
    }
    return gooch_tones(s.base, t);
}

// Gooch et al. 1999, §5.2.1: bands from the random table around the part's principal axis, plus
// Phong highlights from lights in the directions of an icosahedron's vertices, specular power 40,
// coefficient 0.3. Baked: the band texture at u = s·(1 + n·w)/2 (w = obb.axes[1], the table
// resampled as a cosine distribution) and the highlight map by the eye-space normal. Procedural:
// the viewer's table by the angle around the axis, and the six lights facing the viewer.
fn shade_metal(s: Surface, part: Part, normal_in_render: vec3<f32>) -> vec3<f32> {
    let tint = mix(vec3<f32>(0.78, 0.80, 0.84), s.base, 0.25);
    // A little diffuse light so that flat faces (one band each) still read apart.
    let diffuse = 0.75 + 0.25 * max(dot(s.n, s.l), 0.0);
    if has(LOOKUP_METAL) {
        let u = lookups.metal.x * 0.5 * (1.0 + dot(normal_in_render, part.axis1.xyz));
        let band = textureSampleLevel(metal_bands, repeat_sampler, vec2<f32>(u, 0.5), 0.0).r;
        let uv = env_uv(s.n, has(LOOKUP_METAL_SPHERE));
        let highlight = textureSampleLevel(metal_highlights, clamp_sampler, uv, 0.0).r;
        return min(tint * mix(0.4, 1.0, band) * diffuse + vec3<f32>(highlight), vec3<f32>(1.0));
    }
    let u = atan2(dot(normal_in_render, part.axis1.xyz), dot(normal_in_render, part.axis2.xyz)) / (2.0 * PI);
    let band = metal_table(u * 2.0);
    var c = tint * mix(0.4, 1.0, band) * diffuse;
    let phi = 1.618034;
    var lights = array<vec3<f32>, 6>(
        vec3<f32>(0.0, 1.0, phi), vec3<f32>(0.0, -1.0, phi), vec3<f32>(phi, 0.0, 1.0),
        vec3<f32>(-phi, 0.0, 1.0), vec3<f32>(1.0, phi, 0.0), vec3<f32>(-1.0, phi, 0.0));
    var highlight = 0.0;
    for (var k = 0u; k < 6u; k = k + 1u) {
        let h = normalize(normalize(lights[k]) + s.v);
        highlight = highlight + 0.3 * pow(max(dot(s.n, h), 0.0), 40.0);
    }
    return min(c + vec3<f32>(highlight), vec3<f32>(1.0));
}

// Freudenberg's soft threshold: ink = clamp(c · (1 − (T + I))) of a halftone T against the
// intensity I, screen-space (ten Bosch's "simple hatching"). Baked: T from the halftone's mip chain
// (the tile's screen size gives the gradients, so any control flow may sample it). Procedural: a
// line pattern, and a second, crossing set of strokes where the surface is darker.
fn shade_hatch(s: Surface) -> vec3<f32> {
    let intensity = 0.12 + 0.88 * max(dot(s.n, s.l), 0.0);
    let paper = vec3<f32>(0.99, 0.98, 0.95);
    let pen = vec3<f32>(0.08, 0.08, 0.1);
    if has(LOOKUP_HATCH) {
        let texel = 1.0 / lookups.hatch.x;
        let t = textureSampleGrad(hatching, repeat_sampler, s.frag * texel, vec2<f32>(texel, 0.0), vec2<f32>(0.0, texel)).r;
        return mix(paper, pen, clamp(lookups.hatch.y * (1.0 - (t + intensity)), 0.0, 1.0));
    }
    let period = frame.style_params.z;
    let c = frame.style_params.w;
    let a = (s.frag.x + s.frag.y) * 0.70710678 / period;
    let b = (s.frag.x - s.frag.y) * 0.70710678 / period;
    let t1 = abs(fract(a) - 0.5) * 2.0;
    let t2 = abs(fract(b) - 0.5) * 2.0;
    let ink1 = clamp(c * (1.0 - (t1 + intensity)), 0.0, 1.0);
    let ink2 = clamp(c * (1.0 - (t2 + intensity + 0.4)), 0.0, 1.0);
    let ink = max(ink1, ink2);
    return mix(paper, pen, ink);
}

@fragment
fn fs_main(in: VertexOut, @builtin(front_facing) front_facing: bool) -> GBufferOut {
    // Derivatives first (uniform control flow): the face normal for meshes without normals.
    let dpx = dpdx(in.position_in_render);
    let dpy = dpdy(in.position_in_render);
    let ortho = frame.camera_position.w > 0.5;
    let backward = vec3<f32>(frame.view_from_render[0].z, frame.view_from_render[1].z, frame.view_from_render[2].z);
    let to_camera = select(normalize(frame.camera_position.xyz - in.position_in_render), backward, ortho);

    var face_normal = cross(dpx, dpy);
    if length(face_normal) < 1e-20 {
        face_normal = to_camera;
    }
    face_normal = normalize(face_normal);
    if dot(face_normal, to_camera) < 0.0 {
        face_normal = -face_normal;
    }
    var normal = in.normal_in_render;
    if length(normal) < 1e-12 {
        normal = face_normal;
    } else {
        normal = normalize(normal);
        // Open surfaces and mirrored instances: show the side that faces the viewer.
        let facing = front_facing != (in.mirrored != 0u);
        if !facing {
            normal = -normal;
        }
    }

    let position_in_view = (frame.view_from_render * vec4<f32>(in.position_in_render, 1.0)).xyz;
    var s: Surface;
    s.position_in_render = in.position_in_render;
    s.n = normalize((frame.view_from_render * vec4<f32>(normal, 0.0)).xyz);
    s.l = normalize(frame.light_in_view.xyz);
    s.v = select(normalize(-position_in_view), vec3<f32>(0.0, 0.0, 1.0), ortho);
    let material = material_at(in.material);
    s.base = material.base_color.rgb;
    s.roughness = material.roughness;
    s.frag = in.clip.xy;

    let part = part_at(in.part);
    var style = frame.scene_style;
    if frame.use_part_styles != 0u && part.style_hint != NO_STYLE {
        style = part.style_hint;
    }
    if countOneBits(STYLES) == 1u {
        style = firstTrailingBit(STYLES);
    }
    var color = s.base;
    if may_draw(STYLE_GRADIENT) && style == STYLE_GRADIENT {
        color = shade_gradient(s, part);
    } else if may_draw(STYLE_CEL) && style == STYLE_CEL {
        color = shade_cel(s);
    } else if may_draw(STYLE_GOOCH) && style == STYLE_GOOCH {
        color = shade_gooch(s);
    } else if may_draw(STYLE_GOOCHEL) && style == STYLE_GOOCHEL {
        color = shade_goochel(s);
    } else if may_draw(STYLE_METAL) && style == STYLE_METAL {
        color = shade_metal(s, part, normal);
    } else if may_draw(STYLE_HATCH) && style == STYLE_HATCH {
        color = shade_hatch(s);
    } else if may_draw(STYLE_PHONG) {
        color = shade_phong(s);
    }
    if part.flat >= 0.0 {
        color = vec3<f32>(part.flat);
    }
    if (part.flags & PART_REFERENCE) != 0u {
        color = mix(color, REFERENCE_TINT.rgb, REFERENCE_TINT.a);
    } else if (part.flags & PART_SELECTED) != 0u {
        color = mix(color, SELECTED_TINT.rgb, SELECTED_TINT.a);
    }

    var out: GBufferOut;
    out.color = vec4<f32>(color, 1.0);
    out.normal = vec4<f32>(s.n, 0.0);
    out.depth = -position_in_view.z;
    out.part = in.part + 1u;
    return out;
}
