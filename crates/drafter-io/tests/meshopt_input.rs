//! Compressed input: `tests/data/assembly-gltfpack-cc.glb` is `samples/assembly.glb` as gltfpack
//! 1.3.0 writes it with `-cc` (EXT_meshopt_compression with the octahedral and quaternion filters,
//! KHR_mesh_quantization). It imports to the same scene as the source, up to the quantization.

use std::path::Path;

#[test]
fn gltfpack_cc_output_imports_like_its_source() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let packed = drafter_io::import(&root.join("tests/data/assembly-gltfpack-cc.glb")).expect("imports");
    let source = drafter_io::import(&root.join("../../samples/assembly.glb")).expect("imports");
    let (a, b) = (&packed.scene, &source.scene);
    assert_eq!(a.instances.len(), b.instances.len());
    assert_eq!(a.instanced_triangle_count(), b.instanced_triangle_count());
    let (ba, bb) = (a.world_bounds(), b.world_bounds());
    let size = (bb.max - bb.min).length();
    // gltfpack quantizes positions to 14 bits of each mesh's extent by default.
    assert!((ba.min - bb.min).length() < 1e-3 * size && (ba.max - bb.max).length() < 1e-3 * size, "{ba:?} vs {bb:?}");
}
