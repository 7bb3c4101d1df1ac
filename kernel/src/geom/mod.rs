//! Shared vocabulary: rays, boxes, primitives, hits. Algorithms depend on these, never the reverse.

mod aabb;
mod hit;
mod primitive;
mod ray;
pub mod spawn;

pub(crate) use aabb::corners_contain;
pub use aabb::Aabb;
pub use hit::{closer, Barycentrics, Hit, TriangleHit};
pub use primitive::{Primitive, Sphere, Triangle, VertexError};
pub use ray::Ray;
