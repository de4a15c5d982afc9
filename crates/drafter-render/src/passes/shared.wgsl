// Declarations every pass that draws the scene shares: prepended to gbuffer.wgsl, lines.wgsl and
// shadow.wgsl by their modules (`passes::shader_source`), so each exists once. Keep them in sync
// with gpu_types.rs (FrameUniforms, InstanceGpu): `passes::tests` checks their sizes. Each of those
// passes binds the instance table as `instance_table` (a texture_2d<u32>; table.rs).

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

// One mesh instance (gpu_types::InstanceGpu), in the instance table indexed by instance_index.
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

// Instance i: 8 texels.
fn instance_at(i: u32) -> Instance {
    let t = i * 8u;
    var inst: Instance;
    inst.render_from_object = mat4x4<f32>(
        bitcast<vec4<f32>>(textureLoad(instance_table, table_coord(t), 0)),
        bitcast<vec4<f32>>(textureLoad(instance_table, table_coord(t + 1u), 0)),
        bitcast<vec4<f32>>(textureLoad(instance_table, table_coord(t + 2u), 0)),
        bitcast<vec4<f32>>(textureLoad(instance_table, table_coord(t + 3u), 0)),
    );
    inst.normal_col0 = bitcast<vec4<f32>>(textureLoad(instance_table, table_coord(t + 4u), 0));
    inst.normal_col1 = bitcast<vec4<f32>>(textureLoad(instance_table, table_coord(t + 5u), 0));
    inst.normal_col2 = bitcast<vec4<f32>>(textureLoad(instance_table, table_coord(t + 6u), 0));
    let ids = textureLoad(instance_table, table_coord(t + 7u), 0);
    inst.label_base = ids.x;
    inst.mirrored = ids.y;
    inst.label_count = ids.z;
    inst.pad = ids.w;
    return inst;
}
