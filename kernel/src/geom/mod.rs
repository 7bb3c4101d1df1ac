//! Shared vocabulary: rays, boxes, primitives, hits. Algorithms depend on these, never the reverse.

mod aabb;
mod hit;
mod primitive;
mod ray;
pub mod spawn;

pub(crate) use aabb::corners_contain;
pub use aabb::Aabb;
pub use hit::{closer, Hit};
pub use primitive::{Primitive, Sphere, Triangle};
pub use ray::Ray;
