//! One object ready for queries: its accelerator (of the renderer's family), its place in the
//! global id order, its material and motion.

use super::scene::Shape;
use crate::accel::{Accel, AccelFamily, AccelMemory, BuildError, Counters, Nearest};
use crate::geom::{Aabb, Barycentrics, Primitive, Ray, Sphere, Triangle, VertexError};
use crate::scalar::Scalar;

/// An object's accelerator, over its kind of primitive.
pub(super) enum ShapeAccel<'a, S: Scalar, F: AccelFamily<S>> {
    Triangles(F::Accel<'a, Triangle<S>>),
    Spheres(F::Accel<'a, Sphere<S>>),
}

impl<S: Scalar, F: AccelFamily<S>> Clone for ShapeAccel<'_, S, F> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<S: Scalar, F: AccelFamily<S>> Copy for ShapeAccel<'_, S, F> {}

impl<S: Scalar, F: AccelFamily<S>> core::fmt::Debug for ShapeAccel<'_, S, F> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Triangles(a) => f.debug_tuple("Triangles").field(a).finish(),
            Self::Spheres(a) => f.debug_tuple("Spheres").field(a).finish(),
        }
    }
}

impl<'a, S: Scalar, F: AccelFamily<S>> ShapeAccel<'a, S, F> {
    /// Builds `shape`'s accelerator into `memory`. Never inlined: the builders' working memory
    /// (BVH bins and pending nodes) then sits on the stack once, not once per
    /// primitive type.
    #[inline(never)]
    pub(super) fn build(
        shape: Shape<'a, S>,
        options: &F::Options,
        memory: &mut AccelMemory<'a, S>,
    ) -> Result<Self, BuildError> {
        match shape {
            Shape::Triangles(t) => F::build(options, t, memory).map(Self::Triangles),
            Shape::Spheres(s) => F::build(options, s, memory).map(Self::Spheres),
        }
    }

    #[inline]
    pub(super) fn nearest<C: Counters>(&self, ray: &Ray<S>, c: &mut C) -> Option<Nearest<S>> {
        match self {
            Self::Triangles(a) => a.nearest_counted(ray, c),
            Self::Spheres(a) if F::SPHERES => a.nearest_counted(ray, c),
            Self::Spheres(_) => None,
        }
    }

    #[inline]
    pub(super) fn occluded<C: Counters>(&self, ray: &Ray<S>, c: &mut C) -> bool {
        match self {
            Self::Triangles(a) => a.occluded_counted(ray, c),
            Self::Spheres(a) if F::SPHERES => a.occluded_counted(ray, c),
            Self::Spheres(_) => false,
        }
    }
}

/// Room for one object's built accelerator and placement in the caller's memory
/// ([`crate::render::RenderMemory::objects`], one slot per object, filled by the renderer).
/// Opaque: make arrays of [`ObjectSlot::EMPTY`].
pub struct ObjectSlot<'a, S: Scalar, F: AccelFamily<S> = crate::accel::AnyFamily>(
    pub(super) Option<ObjectGeom<'a, S, F>>,
);

impl<S: Scalar, F: AccelFamily<S>> Clone for ObjectSlot<'_, S, F> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<S: Scalar, F: AccelFamily<S>> Copy for ObjectSlot<'_, S, F> {}

impl<S: Scalar, F: AccelFamily<S>> core::fmt::Debug for ObjectSlot<'_, S, F> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_tuple("ObjectSlot").field(&self.0).finish()
    }
}

impl<S: Scalar, F: AccelFamily<S>> ObjectSlot<'_, S, F> {
    /// An unused slot.
    pub const EMPTY: Self = Self(None);
}

/// A filled slot as the renderer's top-level BVH sees it: its object's box over the whole
/// shutter (empty objects and unused slots: a point at the origin, never entered by a query
/// that matters, as they hold nothing).
impl<S: Scalar, F: AccelFamily<S>> Primitive<S> for ObjectSlot<'_, S, F> {
    fn bounds(&self) -> Aabb<S> {
        self.0
            .map_or(Aabb::new([S::ZERO; 3], [S::ZERO; 3]), |o| o.swept)
    }
    fn check(&self) -> Result<(), VertexError> {
        Ok(())
    }
    fn hit_t(&self, ray: &S::RayData, t_min: S, t_max: S) -> Option<S> {
        let b = self.bounds();
        S::slab(ray, &b.lo, &b.hi, t_min, t_max)
    }
    fn hit_uv(&self, _ray: &S::RayData) -> Barycentrics<S> {
        Barycentrics::ZERO
    }
}

/// An object ready for queries.
pub(crate) struct ObjectGeom<'a, S: Scalar, F: AccelFamily<S>> {
    pub(super) accel: ShapeAccel<'a, S, F>,
    pub(super) shape: Shape<'a, S>,
    /// Global id of the object's first primitive.
    pub(super) base: u32,
    /// Material index (checked).
    pub(crate) material: u32,
    /// Emitted radiance (checked).
    pub(crate) emission: super::scene::Rgb,
    /// Reflects and emits on the front only ([`super::Object::one_sided`]).
    pub(crate) one_sided: bool,
    /// Radiance its surfaces emit: [`super::Object::emission`] plus an emissive material's
    /// (zero: not an emitter).
    pub(crate) emitted: super::scene::Rgb,
    /// Emissive primitives of the objects before this one: for an emitter, the index of its
    /// first primitive among the scene's emissive primitives ([`super::emitters`]).
    pub(crate) emitter_base: u32,
    /// Per-triangle vertex normals, empty or one entry per triangle (checked).
    pub(super) vertex_normals: &'a [[[f32; 3]; 3]],
    /// Motion over the shutter, `None` when static.
    pub(super) motion: Option<[f32; 3]>,
    /// World box over the whole shutter interval (for a static object, its primitives' box).
    pub(super) swept: Aabb<S>,
}

impl<S: Scalar, F: AccelFamily<S>> Clone for ObjectGeom<'_, S, F> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<S: Scalar, F: AccelFamily<S>> Copy for ObjectGeom<'_, S, F> {}

impl<S: Scalar, F: AccelFamily<S>> core::fmt::Debug for ObjectGeom<'_, S, F> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("ObjectGeom")
            .field("accel", &self.accel)
            .field("base", &self.base)
            .field("material", &self.material)
            .field("motion", &self.motion)
            .finish_non_exhaustive()
    }
}
