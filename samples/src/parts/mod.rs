//! The parametric parts. Each is a parameter struct with documented defaults and a `build` that tessellates it
//! into a closed [`TriMesh`](crate::solid::TriMesh), face by face (see [`crate::solid`]). Units are metres.

pub mod base_plate;
pub mod bracket;
pub mod fasteners;
pub mod gear;
pub mod shaft;

pub use base_plate::{BasePlate, PlateHole};
pub use bracket::Bracket;
pub use fasteners::{HexBolt, HexNut};
pub use gear::SpurGear;
pub use shaft::FlangedShaft;
