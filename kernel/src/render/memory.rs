//! The caller's memory for a render: one slot per object and the accelerators' buffers.

use super::objects::ObjectSlot;
use super::scene::{Object, Shape};
use crate::accel::{AccelFamily, AccelMemory, AnyFamily, MemoryNeeded};
use crate::scalar::Scalar;

/// The caller's memory for [`crate::render::Renderer::new`]: at least what
/// [`memory_needed`] gives (longer is fine). Objects take their share from the front, in
/// scene order.
#[derive(Debug)]
pub struct RenderMemory<'a, S: Scalar, F: AccelFamily<S> = AnyFamily> {
    /// One slot per object.
    pub objects: &'a mut [ObjectSlot<'a, S, F>],
    /// The objects' accelerators.
    pub accel: AccelMemory<'a, S>,
}

impl<S: Scalar, F: AccelFamily<S>> Default for RenderMemory<'_, S, F> {
    /// No memory at all: enough for a scene without objects.
    fn default() -> Self {
        Self {
            objects: &mut [],
            accel: AccelMemory::default(),
        }
    }
}

/// Buffer lengths (elements, not bytes) a scene needs: the object count and the sum of its
/// objects' accelerator memory.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RenderMemoryNeeded {
    /// Length of [`RenderMemory::objects`]: the scene's object count.
    pub objects: usize,
    /// The lengths of [`RenderMemory::accel`]'s buffers.
    pub accel: MemoryNeeded,
}

impl RenderMemoryNeeded {
    /// The total in bytes for mode `S` and family `F`.
    #[must_use]
    pub const fn bytes<S: Scalar, F: AccelFamily<S>>(&self) -> usize {
        self.objects
            .saturating_mul(size_of::<ObjectSlot<'_, S, F>>())
            .saturating_add(self.accel.bytes::<S>())
    }
}

/// What a scene's objects need with family `F` built with `options`, and the top-level BVH
/// over them (two objects or more). An object whose build the
/// sizing already rejects (a grid's counting pass) needs nothing here: its build reports the
/// error.
#[must_use]
pub fn memory_needed<S: Scalar, F: AccelFamily<S>>(
    objects: &[Object<'_, S>],
    options: &F::Options,
) -> RenderMemoryNeeded {
    let accel = objects.iter().fold(MemoryNeeded::NONE, |sum, o| {
        let need = match o.shape {
            Shape::Triangles(t) => F::memory_needed(options, t),
            Shape::Spheres(s) if F::SPHERES => F::memory_needed(options, s),
            Shape::Spheres(_) => Ok(MemoryNeeded::NONE),
        };
        sum.add(need.unwrap_or(MemoryNeeded::NONE))
    });
    // The objects' top-level BVH, for two objects or more.
    let top = if objects.len() >= 2 {
        MemoryNeeded::bvh(objects.len())
    } else {
        MemoryNeeded::NONE
    };
    RenderMemoryNeeded {
        objects: objects.len(),
        accel: accel.add(top),
    }
}
