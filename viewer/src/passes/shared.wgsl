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

// One mesh instance (gpu_types::InstanceGpu), in a storage buffer indexed by instance_index.
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
