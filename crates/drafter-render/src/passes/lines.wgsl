// Lines pass: every baked edge (and every silhouette of this frame) as a screen-space quad of a width
// in pixels (6 vertices per segment, vertex 6i + k being corner k of segment i, in one draw),
// blended over the display output.
// The quad is the segment's capsule: extended by the half-width at both ends and cut round in the
// fragment shader, so consecutive segments join without gaps. Hidden parts are discarded by
// comparing the line's view depth with the G-buffer's linear depth at the nearest point of the
// segment (and one texel to either side), within a tolerance.
// Frame is in shared.wgsl. Keep the structs in sync with gpu_types.rs (FrameUniforms, InstanceGpu, LineSegmentGpu,
// LinesUniforms) and the class codes (`kind`) with edges::LineClass.

struct Segment {
    a: vec3<f32>,
    instance: u32,
    b: vec3<f32>,
    kind: u32,
}

struct Lines {
    clip_from_view: mat4x4<f32>,
    outline_color: vec4<f32>,
    crease_color: vec4<f32>,
    half_widths: vec4<f32>, // outline, crease, outer extra (px); near plane
    depth_tolerance: vec4<f32>, // relative, pixel footprints, footprint per depth, footprint constant
}

const CLASS_CREASE: u32 = 1u;
// Relative depth jump across a crease that makes it a contour (passes::lines::CONTOUR_DEPTH_JUMP).
const CONTOUR_DEPTH_JUMP: f32 = 0.1;

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<uniform> lines: Lines;
@group(0) @binding(2) var instance_table: texture_2d<u32>;
@group(1) @binding(0) var linear_depth_tex: texture_2d<f32>;
@group(1) @binding(1) var part_id_tex: texture_2d<u32>;
@group(2) @binding(0) var segment_table: texture_2d<u32>;

// The render-from-object transform of instance i: the first 4 of its 8 texels (table.rs; the
// record is gpu_types::InstanceGpu, `Instance` in shared.wgsl). Every vertex of a segment reads
// it, and only it.
fn instance_transform_at(i: u32) -> mat4x4<f32> {
    let t = i * 8u;
    return mat4x4<f32>(
        bitcast<vec4<f32>>(textureLoad(instance_table, table_coord(t), 0)),
        bitcast<vec4<f32>>(textureLoad(instance_table, table_coord(t + 1u), 0)),
        bitcast<vec4<f32>>(textureLoad(instance_table, table_coord(t + 2u), 0)),
        bitcast<vec4<f32>>(textureLoad(instance_table, table_coord(t + 3u), 0)),
    );
}

// Segment i of the bound table (table.rs): 2 texels.
fn segment_at(i: u32) -> Segment {
    let first = textureLoad(segment_table, table_coord(i * 2u), 0);
    let second = textureLoad(segment_table, table_coord(i * 2u + 1u), 0);
    var s: Segment;
    s.a = bitcast<vec3<f32>>(first.xyz);
    s.instance = first.w;
    s.b = bitcast<vec3<f32>>(second.xyz);
    s.kind = second.w;
    return s;
}

struct VertexOut {
    @builtin(position) position: vec4<f32>,
    // Segment at_ends in target pixels (y down) and their view depths.
    @location(0) @interpolate(flat) a_px: vec2<f32>,
    @location(1) @interpolate(flat) b_px: vec2<f32>,
    @location(2) @interpolate(flat) depths: vec2<f32>,
    @location(3) @interpolate(flat) kind: u32,
}

fn to_pixels(view: vec3<f32>) -> vec2<f32> {
    let clip = lines.clip_from_view * vec4<f32>(view, 1.0);
    let ndc = clip.xy / clip.w;
    return vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5) * frame.viewport.xy;
}

fn is_outline(kind: u32) -> bool {
    return kind != CLASS_CREASE;
}

@vertex
fn vs_main(@builtin(vertex_index) vertex: u32) -> VertexOut {
    let v = vertex % 6u;
    let s = segment_at(vertex / 6u);
    let render_from_object = instance_transform_at(s.instance);
    var a = (frame.view_from_render * (render_from_object * vec4<f32>(s.a, 1.0))).xyz;
    var b = (frame.view_from_render * (render_from_object * vec4<f32>(s.b, 1.0))).xyz;
    var out: VertexOut;
    out.kind = s.kind;
    // Clip against the near plane (view space looks down -z).
    let near = -lines.half_widths.w;
    if a.z > near && b.z > near {
        out.position = vec4<f32>(2.0, 2.0, 2.0, 1.0); // outside the clip volume: nothing drawn
        return out;
    }
    if a.z > near {
        a = mix(a, b, (a.z - near) / (a.z - b.z));
    } else if b.z > near {
        b = mix(b, a, (b.z - near) / (b.z - a.z));
    }
    let a_px = to_pixels(a);
    let b_px = to_pixels(b);
    out.a_px = a_px;
    out.b_px = b_px;
    out.depths = vec2<f32>(-a.z, -b.z);

    var hw = select(lines.half_widths.y, lines.half_widths.x + lines.half_widths.z, is_outline(s.kind));
    hw = hw + 1.0; // room for the anti-aliased edge
    let d = b_px - a_px;
    let len = length(d);
    let along = select(vec2<f32>(1.0, 0.0), d / len, len > 1e-4);
    let across = vec2<f32>(-along.y, along.x);
    // Two triangles: corners (at_end, side) = (0,-1) (1,-1) (1,1) / (0,-1) (1,1) (0,1).
    var at_ends = array<f32, 6>(0.0, 1.0, 1.0, 0.0, 1.0, 0.0);
    var sides = array<f32, 6>(-1.0, -1.0, 1.0, -1.0, 1.0, 1.0);
    let at_end = at_ends[v];
    let side = sides[v];
    let p = select(a_px - along * hw, b_px + along * hw, at_end > 0.5) + across * side * hw;
    let ndc = vec2<f32>(p.x / frame.viewport.x * 2.0 - 1.0, 1.0 - p.y / frame.viewport.y * 2.0);
    out.position = vec4<f32>(ndc, 0.5, 1.0);
    return out;
}

fn part_at(p: vec2<f32>) -> u32 {
    let size = vec2<i32>(textureDimensions(part_id_tex));
    return textureLoad(part_id_tex, clamp(vec2<i32>(floor(p)), vec2<i32>(0), size - 1), 0).r;
}

// G-buffer linear depth at a pixel; the background (0) is infinitely far.
fn scene_depth(p: vec2<f32>) -> f32 {
    let size = vec2<i32>(textureDimensions(linear_depth_tex));
    let q = clamp(vec2<i32>(floor(p)), vec2<i32>(0), size - 1);
    let d = textureLoad(linear_depth_tex, q, 0).r;
    return select(d, 3.0e38, d <= 0.0);
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    let p = in.position.xy;
    let ab = in.b_px - in.a_px;
    let len2 = dot(ab, ab);
    let t = select(0.0, clamp(dot(p - in.a_px, ab) / len2, 0.0, 1.0), len2 > 1e-8);
    let c = in.a_px + ab * t;
    let dist = length(p - c);

    let n = select(vec2<f32>(0.0, 1.0), vec2<f32>(-ab.y, ab.x) / sqrt(len2), len2 > 1e-8);

    // A crease that lies on the contour right now — the part id or the depth jumps across it — is
    // drawn as an outline: black and heavier, as Gooch et al. draw every silhouette.
    let side = lines.half_widths.x + 1.5;
    let id_l = part_at(c + n * side);
    let id_r = part_at(c - n * side);
    let d_l = scene_depth(c + n * side);
    let d_r = scene_depth(c - n * side);
    let contour = id_l != id_r || abs(d_l - d_r) > CONTOUR_DEPTH_JUMP * min(d_l, d_r);
    let outline = is_outline(in.kind) || contour;

    // Width: the outer outline is heavier, on the background side only.
    var hw = select(lines.half_widths.y, lines.half_widths.x, outline);
    if outline && part_at(p) == 0u {
        hw = hw + lines.half_widths.z;
    }
    let coverage = clamp(hw + 0.5 - dist, 0.0, 1.0);
    if coverage <= 0.0 {
        discard;
    }

    // Visibility at the segment's nearest point: perspective-correct view depth there, against the
    // farthest G-buffer depth at that point and 1.5 texels to either side (a silhouette's own
    // surface turns away steeply beside it).
    let persp = frame.camera_position.w < 0.5;
    let da = in.depths.x;
    let db = in.depths.y;
    let line_depth = select(mix(da, db, t), 1.0 / mix(1.0 / da, 1.0 / db, t), persp);
    let surface = max(scene_depth(c), max(scene_depth(c + n * 1.5), scene_depth(c - n * 1.5)));
    let footprint = lines.depth_tolerance.z * line_depth + lines.depth_tolerance.w;
    let tolerance = lines.depth_tolerance.x * line_depth + lines.depth_tolerance.y * footprint;
    if line_depth > surface + tolerance {
        discard;
    }
    let color = select(lines.crease_color, lines.outline_color, outline);
    return vec4<f32>(color.rgb, color.a * coverage);
}
