//! glTF accessors decoded once for the workspace: component types, the checked layout of an
//! accessor's elements in its buffer view, and the decoding of elements into floats (normalized
//! integers by the glTF 2.0 rule, KHR_mesh_quantization's integer types) or indices.
//!
//! The importer (drafter-io, over the gltf crate's typed accessors) and this crate's readers of baked
//! files (over the JSON they parse) describe an accessor to these functions and decode it here; what
//! differs between them is only where the numbers come from and how an error names its place.

/// A buffer view's `target` for vertex attributes (the GL enum ARRAY_BUFFER).
pub const ARRAY_BUFFER: u32 = 34962;
/// A buffer view's `target` for indices (the GL enum ELEMENT_ARRAY_BUFFER).
pub const ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// Components per element of an accessor's `type` (`"SCALAR"` 1 … `"MAT4"` 16); `None` for any
/// other name.
pub fn components(type_name: &str) -> Option<usize> {
    Some(match type_name {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" | "MAT2" => 4,
        "MAT3" => 9,
        "MAT4" => 16,
        _ => return None,
    })
}

/// An accessor's `componentType` (glTF 2.0, "Accessor Data Types").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ComponentType {
    I8,
    U8,
    I16,
    U16,
    U32,
    F32,
}

impl ComponentType {
    /// The type of a `componentType` code (5120 BYTE … 5126 FLOAT); `None` for any other number.
    pub fn from_code(code: u64) -> Option<Self> {
        Some(match code {
            5120 => Self::I8,
            5121 => Self::U8,
            5122 => Self::I16,
            5123 => Self::U16,
            5125 => Self::U32,
            5126 => Self::F32,
            _ => return None,
        })
    }

    /// The `componentType` code of this type, as written in a glTF.
    pub const fn code(self) -> u32 {
        match self {
            Self::I8 => 5120,
            Self::U8 => 5121,
            Self::I16 => 5122,
            Self::U16 => 5123,
            Self::U32 => 5125,
            Self::F32 => 5126,
        }
    }

    /// Bytes per component.
    pub fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::U32 | Self::F32 => 4,
        }
    }

    /// Decodes the component at the start of `b` (the caller guarantees `size()` bytes). Normalized
    /// integers follow the spec's `max(c / MAX, -1)` rule; other integers are their value.
    #[inline]
    pub fn decode(self, b: &[u8], normalized: bool) -> f32 {
        match self {
            Self::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            Self::I8 => {
                let v = f32::from(b[0] as i8);
                if normalized { (v / 127.0).max(-1.0) } else { v }
            }
            Self::U8 => {
                let v = f32::from(b[0]);
                if normalized { v / 255.0 } else { v }
            }
            Self::I16 => {
                let v = f32::from(i16::from_le_bytes([b[0], b[1]]));
                if normalized { (v / 32767.0).max(-1.0) } else { v }
            }
            Self::U16 => {
                let v = f32::from(u16::from_le_bytes([b[0], b[1]]));
                if normalized { v / 65535.0 } else { v }
            }
            Self::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
        }
    }

    /// Decodes an unsigned integer component (an index) at the start of `b`; `None` for the
    /// signed and float types, which indices may not use.
    #[inline]
    fn index(self, b: &[u8]) -> Option<u32> {
        match self {
            Self::U8 => Some(u32::from(b[0])),
            Self::U16 => Some(u32::from(u16::from_le_bytes([b[0], b[1]]))),
            Self::U32 => Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            _ => None,
        }
    }
}

/// Where an accessor's elements lie in its buffer view, checked: `count` elements of `element`
/// bytes, the first at `start`, one every `stride` bytes, all inside the view.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    pub start: usize,
    pub stride: usize,
    pub count: usize,
    pub element: usize,
}

/// Why a [`Layout`] does not fit its buffer view (the caller names the place).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LayoutError {
    /// A `byteStride` smaller than one element.
    StrideTooSmall,
    /// The last element ends past the view (or the arithmetic overflows).
    OutsideView,
}

impl Layout {
    /// The layout of `count` elements of `element` bytes at `offset` in a view of `view_length`
    /// bytes with the given `byteStride` (`None` or 0: tightly packed). Every number may come from
    /// an untrusted file: the arithmetic is checked.
    pub fn new(
        view_length: usize,
        byte_stride: Option<usize>,
        offset: usize,
        count: usize,
        element: usize,
    ) -> Result<Self, LayoutError> {
        let stride = match byte_stride {
            None | Some(0) => element,
            Some(s) if s >= element => s,
            Some(_) => return Err(LayoutError::StrideTooSmall),
        };
        // The last element ends at offset + (count − 1)·stride + element; an empty accessor reads
        // nothing and may lie anywhere.
        let end = match count {
            0 => Some(0),
            _ => (count - 1).checked_mul(stride).and_then(|x| x.checked_add(offset)?.checked_add(element)),
        };
        match end {
            Some(end) if end <= view_length => Ok(Layout { start: offset, stride, count, element }),
            _ => Err(LayoutError::OutsideView),
        }
    }

    /// Whether the elements are tightly packed (no bytes between them).
    pub fn is_packed(&self) -> bool {
        self.stride == self.element
    }

    /// Each element's bytes; `view` is the buffer view the layout was checked against.
    pub fn elements<'a>(&self, view: &'a [u8]) -> impl ExactSizeIterator<Item = &'a [u8]> + use<'a> {
        let Layout { start, stride, element, .. } = *self;
        (0..self.count).map(move |i| &view[start + i * stride..start + i * stride + element])
    }

    /// The bytes of tightly packed elements (`None` when they are strided).
    pub fn packed<'a>(&self, view: &'a [u8]) -> Option<&'a [u8]> {
        // In range when there is an element (checked by `new`); an empty accessor may lie anywhere.
        self.is_packed().then(|| view.get(self.start..self.start + self.count * self.element).unwrap_or_default())
    }
}

/// Decodes the elements of `layout` in `view` as `N` components of `ty` each.
pub fn read_vectors<const N: usize>(
    view: &[u8],
    layout: &Layout,
    ty: ComponentType,
    normalized: bool,
) -> Vec<[f32; N]> {
    let size = ty.size();
    debug_assert_eq!(layout.element, N * size);
    match layout.packed(view) {
        // Tightly packed floats (positions and normals, mostly): one loop without the
        // per-component type dispatch.
        Some(bytes) if ty == ComponentType::F32 => bytes
            .chunks_exact(4 * N)
            .map(|e| std::array::from_fn(|c| f32::from_le_bytes([e[4 * c], e[4 * c + 1], e[4 * c + 2], e[4 * c + 3]])))
            .collect(),
        _ => layout.elements(view).map(|e| std::array::from_fn(|c| ty.decode(&e[c * size..], normalized))).collect(),
    }
}

/// Decodes the elements of `layout` in `view` as unsigned indices of `ty`; `None` when `ty` is not
/// an unsigned integer type.
pub fn read_indices(view: &[u8], layout: &Layout, ty: ComponentType) -> Option<Vec<u32>> {
    if !matches!(ty, ComponentType::U8 | ComponentType::U16 | ComponentType::U32) {
        return None;
    }
    debug_assert_eq!(layout.element, ty.size());
    Some(match layout.packed(view) {
        // Tightly packed (every index buffer we have seen): one loop per component type, so that
        // the type is matched once per buffer, not once per index (a large share of a big parse).
        Some(data) => match ty {
            ComponentType::U8 => data.iter().map(|&b| u32::from(b)).collect(),
            ComponentType::U16 => data.chunks_exact(2).map(|c| u32::from(u16::from_le_bytes([c[0], c[1]]))).collect(),
            _ => data.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect(),
        },
        None => layout.elements(view).map(|e| ty.index(e).unwrap_or_default()).collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalized_components_decode_per_spec() {
        use ComponentType::*;
        assert_eq!(I8.decode(&[0x81], true), -1.0);
        assert_eq!(I8.decode(&[0x80], true), -1.0, "-128 clamps to -1");
        assert_eq!(I8.decode(&[127], true), 1.0);
        assert_eq!(U8.decode(&[255], true), 1.0);
        assert_eq!(I16.decode(&i16::MIN.to_le_bytes(), true), -1.0);
        assert_eq!(U16.decode(&u16::MAX.to_le_bytes(), true), 1.0);
        assert_eq!(U16.decode(&300u16.to_le_bytes(), false), 300.0);
        assert_eq!(F32.decode(&1.5f32.to_le_bytes(), false), 1.5);
        assert_eq!(ComponentType::from_code(5124), None, "INT is not a glTF accessor type");
        for ty in [I8, U8, I16, U16, U32, F32] {
            assert_eq!(ComponentType::from_code(u64::from(ty.code())), Some(ty));
        }
        assert_eq!((components("VEC3"), components("MAT3"), components("vec3")), (Some(3), Some(9), None));
    }

    #[test]
    fn layouts_are_checked_and_strided_elements_read_like_packed_ones() {
        assert_eq!(Layout::new(12, None, 0, 3, 4).map(|l| l.is_packed()), Ok(true));
        assert_eq!(Layout::new(11, None, 0, 3, 4), Err(LayoutError::OutsideView));
        assert_eq!(Layout::new(100, Some(2), 0, 3, 4), Err(LayoutError::StrideTooSmall));
        assert_eq!(Layout::new(8, None, usize::MAX - 2, 2, 4), Err(LayoutError::OutsideView));
        assert!(Layout::new(0, None, 1 << 40, 0, 4).is_ok(), "an empty accessor may lie anywhere");
        // Three u16 indices, packed and with a stride of 4.
        let packed = [1u8, 0, 2, 0, 3, 1];
        let strided = [1u8, 0, 9, 9, 2, 0, 9, 9, 3, 1];
        let ty = ComponentType::U16;
        let a = read_indices(&packed, &Layout::new(6, None, 0, 3, 2).unwrap(), ty).unwrap();
        let b = read_indices(&strided, &Layout::new(10, Some(4), 0, 3, 2).unwrap(), ty).unwrap();
        assert_eq!(a, [1, 2, 259]);
        assert_eq!(a, b);
        assert!(read_indices(&packed, &Layout::new(6, None, 0, 3, 2).unwrap(), ComponentType::I16).is_none());
        let floats: Vec<u8> = [1.0f32, 2.0, 3.0, 4.0].iter().flat_map(|f| f.to_le_bytes()).collect();
        let v: Vec<[f32; 2]> =
            read_vectors(&floats, &Layout::new(16, None, 0, 2, 8).unwrap(), ComponentType::F32, false);
        let w: Vec<[f32; 1]> =
            read_vectors(&floats, &Layout::new(16, Some(8), 4, 2, 4).unwrap(), ComponentType::F32, false);
        assert_eq!(v, [[1.0, 2.0], [3.0, 4.0]]);
        assert_eq!(w, [[2.0], [4.0]]);
    }
}
