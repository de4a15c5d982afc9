// Shadow pass: the model flattened onto the ground from a point light. Screen-space layers (hard:
// 1, umbra + penumbra: 2) accumulate into the mask directly; the soft shadow renders one layer
// into a top-down ground map and resolves the stack of planes from it (fs_resolve).
// Frame and Instance are in shared.wgsl. Keep the structs in sync with gpu_types.rs (Instance, ShadowLayer, Resolve).

struct ShadowLayer {
    clip_from_render: mat4x4<f32>,
    light_position: vec4<f32>,
    plane: vec4<f32>, // x: projection plane height, y: ground height, z: weight
}

struct Resolve {
    render_from_clip: mat4x4<f32>,
    map_rect: vec4<f32>, // min x, min z, width, depth
    foot_ground_count: vec4<f32>, // foot x, foot z, ground y, planes
    target_size: vec4<f32>, // mask width, height
    inverse_scales: array<vec4<f32>, 4>,
}

@group(0) @binding(0) var<uniform> layer: ShadowLayer;

struct VertexIn {
    @location(0) position_in_object: vec3<f32>,
    @location(1) normal_in_object: vec3<f32>,
    @location(2) label: u32,
    @location(3) material: u32,
}

@vertex
fn vs_main(v: VertexIn, instance: InstanceIn) -> @builtin(position) vec4<f32> {
    let p = (instance_from(instance).render_from_object * vec4<f32>(v.position_in_object, 1.0)).xyz;
    let light = layer.light_position.xyz;
    // The ray from the light through p meets the plane y = h at t; points at or above the light's
    // height cast no shadow and are pushed far along their ray instead.
    let h = layer.plane.x;
    let drop = max(light.y - p.y, 1e-6 * max(abs(light.y - h), 1e-12));
    let t = (light.y - h) / drop;
    var q = light + (p - light) * t;
    q.y = layer.plane.y; // moved to the ground
    return layer.clip_from_render * vec4<f32>(q, 1.0);
}

@fragment
fn fs_main() -> @location(0) vec4<f32> {
    return vec4<f32>(layer.plane.z, 0.0, 0.0, 0.0);
}

// The resolve's own group (1), apart from the layer draws' group 0.
@group(1) @binding(0) var<uniform> resolve: Resolve;
@group(1) @binding(1) var ground_map: texture_2d<f32>;
@group(1) @binding(2) var map_sampler: sampler;

// The soft shadow at a mask pixel: the camera ray meets the ground at x; the shadow of plane k,
// moved to the ground, is the ground shadow scaled by s_k about the light's foot point f, so its
// value at x is the map at f + (x − f) / s_k. The planes are averaged.
@fragment
fn fs_resolve(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let uv = frag.xy / resolve.target_size.xy;
    let ndc = vec2<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0);
    let a4 = resolve.render_from_clip * vec4<f32>(ndc, 0.0, 1.0);
    let b4 = resolve.render_from_clip * vec4<f32>(ndc, 1.0, 1.0);
    let a = a4.xyz / a4.w;
    let b = b4.xyz / b4.w;
    let ground = resolve.foot_ground_count.z;
    let dy = b.y - a.y;
    let t = (ground - a.y) / select(dy, 1e-30, abs(dy) < 1e-30);
    if t < 0.0 || abs(dy) < 1e-30 {
        return vec4<f32>(0.0);
    }
    let x = (a + (b - a) * t).xz;
    let foot = resolve.foot_ground_count.xy;
    let n = u32(resolve.foot_ground_count.w);
    var sum = 0.0;
    for (var k = 0u; k < n; k = k + 1u) {
        let s = resolve.inverse_scales[k / 4u][k % 4u];
        let g = foot + (x - foot) * s;
        let map_uv = (g - resolve.map_rect.xy) / resolve.map_rect.zw;
        if all(map_uv >= vec2<f32>(0.0)) && all(map_uv <= vec2<f32>(1.0)) {
            sum = sum + textureSampleLevel(ground_map, map_sampler, map_uv, 0.0).r;
        }
    }
    return vec4<f32>(sum / f32(max(n, 1u)), 0.0, 0.0, 0.0);
}
