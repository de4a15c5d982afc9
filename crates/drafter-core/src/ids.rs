//! Typed indices. Each wraps a `u32` index into the collection named by its type, so a mesh id can not
//! be used where an instance id is meant.

use serde::{Deserialize, Serialize};

macro_rules! typed_id {
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
        #[serde(transparent)]
        pub struct $name(pub u32);

        impl $name {
            /// The index into the owning collection.
            #[inline]
            pub fn index(self) -> usize {
                self.0 as usize
            }
        }

        impl From<usize> for $name {
            #[inline]
            fn from(i: usize) -> Self {
                Self(u32::try_from(i).expect(concat!(stringify!($name), " overflows u32")))
            }
        }

        impl std::fmt::Display for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "{}", self.0)
            }
        }
    };
}

typed_id!(
    /// Index into [`crate::Scene::meshes`].
    MeshId
);
typed_id!(
    /// Index into [`crate::Scene::instances`].
    InstanceId
);
typed_id!(
    /// Index into [`crate::Scene::materials`].
    MaterialId
);
typed_id!(
    /// Index into [`crate::Scene::nodes`].
    NodeId
);
typed_id!(
    /// A part produced by segmentation.
    PartId
);
typed_id!(
    /// Index into [`crate::Topology::edges`].
    EdgeId
);
