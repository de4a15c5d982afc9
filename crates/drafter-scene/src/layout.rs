//! The model's records in the layout the renderer uploads them (`#[repr(C)]`, 16-byte aligned
//! members, bytemuck `Pod`): vertices, instances, parts, materials and line segments. Plain data, no
//! GPU code: the drawing reads the same records.
//!
//! Keep in sync with the declarations of the same names in the viewer's `passes/gbuffer.wgsl`,
//! `passes/shadow.wgsl` and `passes/lines.wgsl` (the viewer's `passes::tests` checks the sizes
//! against the WGSL side); the size assertions at the bottom catch a field added on one side only.

use bytemuck::{Pod, Zeroable};

/// One vertex of a draw batch (`gbuffer.wgsl`, `shadow.wgsl`: `VertexIn`).
///
/// Vertices are split where a position is used by triangles of different part labels or
/// materials, so both are per vertex (flat-interpolated).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Vertex {
    pub position_in_object: [f32; 3],
    /// Zero when the mesh has no normals: the fragment shader then uses the face normal
    /// (screen-space derivatives of the position).
    pub normal_in_object: [f32; 3],
    /// Part label of the triangles using this vertex (index into the instance's part list).
    pub label: u32,
    /// Index into the material table.
    pub material: u32,
}

/// One mesh instance (`shared.wgsl`: `Instance`): the G-buffer and shadow passes read it as vertex
/// attributes stepped per instance (`InstanceIn`), the lines pass from the instance table by a
/// segment's `instance`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct InstanceGpu {
    /// Object → render space (world translated so that the scene centre is the origin, which keeps
    /// f32 precision for CAD coordinates far from the world origin). Column-major.
    pub render_from_object: [[f32; 4]; 4],
    /// Inverse transpose of the upper 3×3 of `render_from_object`, as three padded columns.
    pub normal_from_object: [[f32; 4]; 3],
    /// Where this instance's label → part table starts in the `label_to_part` buffer.
    pub label_base: u32,
    /// 1 when the transform mirrors (negative determinant): front faces are clockwise.
    pub mirrored: u32,
    pub label_count: u32,
    pub _pad: u32,
}

/// Per-part parameters (`gbuffer.wgsl`: `Part`), in the part table indexed by scene-wide part id.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct PartGpu {
    /// Row 0 of the projector matrix, for render-space positions: `p = dot(row, (x, 1))`.
    pub projector_row: [f32; 4],
    /// The oriented box's axes (longest first), w unused. Metal bands run along `axes[0]`.
    pub axes: [[f32; 4]; 3],
    /// Gradient `q`, `f`, `p` and the transfer curve: its index in
    /// [`drafter_core::gradient::TransferCurve::ALL`] in a [`crate::model::Part`], its row in the
    /// bound γ atlas in the uploaded table ([`crate::Model::part_table`]).
    pub gradient: [f32; 4],
    /// Style hint ([`crate::style::shader_index`]) or [`NO_STYLE`].
    pub style_hint: u32,
    /// [`PART_SELECTED`] and [`PART_REFERENCE`]: the editor's selection, tinted by the G-buffer pass.
    pub flags: u32,
    /// A flat grey in [0, 1] drawn instead of the shading, or [`NOT_FLAT`].
    pub flat: f32,
    pub _pad: u32,
}

/// `PartGpu::flags`: the part is selected.
pub const PART_SELECTED: u32 = 1;
/// `PartGpu::flags`: the part is the selection's reference (drawn in a lighter highlight).
pub const PART_REFERENCE: u32 = 2;
/// `PartGpu::flat` of a shaded part.
pub const NOT_FLAT: f32 = -1.0;

/// `PartGpu::style_hint` of a part without a hint: it takes the scene's style.
pub const NO_STYLE: u32 = u32::MAX;

/// A material (`gbuffer.wgsl`: `Material`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct MaterialGpu {
    /// Base colour, in display (non-linear) values: styles mix it as an illustrator would.
    pub base_color: [f32; 4],
    pub metallic: f32,
    pub roughness: f32,
    pub _pad: [f32; 2],
}

/// One line of the lines pass (`lines.wgsl`: `Segment`), in a segment table indexed by
/// `instance_index`: an edge in its mesh's object space, the model instance that places it, and its
/// [`crate::edges::LineClass`] as the shader draws it ([`crate::edges::LineClass::gpu_kind`]).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LineSegmentGpu {
    pub a_in_object: [f32; 3],
    /// Index into the scene's instance buffer.
    pub instance: u32,
    pub b_in_object: [f32; 3],
    pub class: u32,
}

impl LineSegmentGpu {
    pub fn new(a: glam::Vec3, b: glam::Vec3, instance: u32, class: crate::edges::LineClass) -> Self {
        Self { a_in_object: a.to_array(), instance, b_in_object: b.to_array(), class: class.gpu_kind() }
    }
}

const _: () = {
    assert!(size_of::<Vertex>() == 32);
    assert!(size_of::<InstanceGpu>() == 128);
    assert!(size_of::<PartGpu>() == 96);
    assert!(size_of::<MaterialGpu>() == 32);
    assert!(size_of::<LineSegmentGpu>() == 32);
};
