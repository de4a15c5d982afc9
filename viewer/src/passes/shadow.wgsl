// Shadow pass: the model flattened onto the ground plane from a point light, one layer per draw
// set (hard: 1, umbra + penumbra: 2, soft: a stack of planes). Keep the structs in sync with
// gpu_types.rs (Frame, Instance and ShadowLayer).

struct Frame {
    clip_from_render: mat4x4<f32>,
    view_from_render: mat4x4<f32>,
    camera_position: vec4<f32>,
    light_in_view: vec4<f32>,
    viewport: vec4<f32>,
    scene_style: u32,
    use_part_styles: u32,
    cel_steps: u32,
    flags: u32,
    style_params: vec4<f32>,
}

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

struct ShadowLayer {
    light_position: vec4<f32>,
    plane: vec4<f32>, // x: projection plane height, y: ground height, z: weight
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<storage, read> instances: array<Instance>;
@group(1) @binding(0) var<uniform> layer: ShadowLayer;

struct VertexIn {
    @location(0) position_in_object: vec3<f32>,
    @location(1) normal_in_object: vec3<f32>,
    @location(2) label: u32,
    @location(3) material: u32,
}

@vertex
fn vs_main(v: VertexIn, @builtin(instance_index) instance_index: u32) -> @builtin(position) vec4<f32> {
    let p = (instances[instance_index].render_from_object * vec4<f32>(v.position_in_object, 1.0)).xyz;
    let light = layer.light_position.xyz;
    // The ray from the light through p meets the plane y = h at t; points at or above the light's
    // height cast no shadow and are pushed far along their ray instead.
    let h = layer.plane.x;
    let drop = max(light.y - p.y, 1e-6 * max(abs(light.y - h), 1e-12));
    let t = (light.y - h) / drop;
    var q = light + (p - light) * t;
    q.y = layer.plane.y; // moved to the ground
    return frame.clip_from_render * vec4<f32>(q, 1.0);
}

@fragment
fn fs_main() -> @location(0) vec4<f32> {
    return vec4<f32>(layer.plane.z, 0.0, 0.0, 0.0);
}
