//! Shapes, mass properties and contact queries. This is the only module that
//! sees parry: everything it returns is in nalgebra `f64` types and nudge's
//! own structs, so parry can be upgraded (or replaced) here alone.
//!
//! A [`Geometry`] is a compound of convex [`Part`]s placed in the owner's
//! frame (a body's centre-of-mass frame, or an obstacle's frame). Queries
//! return a [`Contact`] whose `normal` points from the second owner (`b`)
//! towards the first (`a`), with `distance > 0` when apart and `< 0` in
//! penetration, and a [`FeaturePair`] naming the touching features so the
//! tangent code can model how the contact point and normal move.

mod contact;
mod feature;
mod mesh;
mod shapes;
mod solid;

pub use contact::{
    Contact, Corner, FlatFace, NearPoint, PartContacts, Placement, contact, flat_faces,
    near_points, part_contacts, part_near_points, point_parabola,
};
pub use feature::{ContactGeometry, FeaturePair, PatchCorner, PoseT, SideFeature};
pub use mesh::Triangles;
pub use shapes::{Geometry, GeometryError, MassProps, Part, PartKind};
pub use solid::{Decomposition, MAX_PIECES, MeshError};
