// Declarations every pass that draws the scene shares: prepended to gbuffer.wgsl, lines.wgsl and
// shadow.wgsl by their modules (`passes::shader_source`), so each exists once. Keep them in sync
// with gpu_types.rs (FrameUniforms, InstanceGpu): `passes::tests` checks their sizes.

// The frame's camera, light and style (gpu_types::FrameUniforms).
struct Frame {
    clip_from_render: mat4x4<f32>,
    view_from_render: mat4x4<f32>,
    camera_position: vec4<f32>, // w = 1: orthographic
    light_in_view: vec4<f32>,
    viewport: vec4<f32>,
    scene_style: u32,
    use_part_styles: u32,
    cel_steps: u32,
    flags: u32,
    style_params: vec4<f32>, // splash-back alpha, beta; hatch period (px); hatch sharpness c
}

// One mesh instance (gpu_types::InstanceGpu).
struct Instance {
    render_from_object: mat4x4<f32>,
    normal_col0: vec4<f32>,
    normal_col1: vec4<f32>,
    normal_col2: vec4<f32>,
    label_base: u32,
    mirrored: u32,
    label_count: u32,
    pad: u32,
}

// Tables (table.rs): arrays in Rgba32Uint textures, TABLE_WIDTH texels a row, an element of n
// texels starting at texel i * n; floats are stored by their bits.
const TABLE_WIDTH: u32 = 1024u;

fn table_coord(texel: u32) -> vec2<u32> {
    return vec2<u32>(texel % TABLE_WIDTH, texel / TABLE_WIDTH);
}

// The instance record as the G-buffer and shadow passes' vertex shaders read it: a second vertex
// buffer, stepped per instance (`gbuffer::instance_layout`). Vertex attributes and not the instance
// table: a CPU rasteriser (the browser's SwiftShader, lavapipe) runs a texture read as a call into
// its sampler, eight of them for every vertex of every instance; an attribute is a plain load.
struct InstanceIn {
    @location(4) render_from_object0: vec4<f32>,
    @location(5) render_from_object1: vec4<f32>,
    @location(6) render_from_object2: vec4<f32>,
    @location(7) render_from_object3: vec4<f32>,
    @location(8) normal_col0: vec4<f32>,
    @location(9) normal_col1: vec4<f32>,
    @location(10) normal_col2: vec4<f32>,
    @location(11) ids: vec4<u32>, // label_base, mirrored, label_count, pad
}

fn instance_from(v: InstanceIn) -> Instance {
    var inst: Instance;
    inst.render_from_object = mat4x4<f32>(v.render_from_object0, v.render_from_object1, v.render_from_object2, v.render_from_object3);
    inst.normal_col0 = v.normal_col0;
    inst.normal_col1 = v.normal_col1;
    inst.normal_col2 = v.normal_col2;
    inst.label_base = v.ids.x;
    inst.mirrored = v.ids.y;
    inst.label_count = v.ids.z;
    inst.pad = v.ids.w;
    return inst;
}
