//! The caller's scene read through its pointers: checked arrays, mode and kind, counts.

use super::failure::Failure;
use super::types::*;
use crate::{RkStatus, RK_KIND_BVH, RK_KIND_BVH4, RK_MODE_F32, RK_MODE_FIXED};
use raykernel::{MemoryNeeded, MAX_PRIMS};

/// The mode and accelerator family a scene names.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Which {
    F32Bvh,
    F32Bvh4,
    FixedBvh,
    FixedBvh4,
}

impl Which {
    /// Whether the crate's features (`render-f32`, `render-fixed`, `render-bvh`,
    /// `render-bvh4`) link this pair. A constant: code for a pair left out is dead, so neither
    /// its build nor its renderer reaches the binary.
    pub(super) const fn linked(self) -> bool {
        let (mode, kind) = match self {
            Self::F32Bvh => (cfg!(feature = "render-f32"), cfg!(feature = "render-bvh")),
            Self::F32Bvh4 => (cfg!(feature = "render-f32"), cfg!(feature = "render-bvh4")),
            Self::FixedBvh => (cfg!(feature = "render-fixed"), cfg!(feature = "render-bvh")),
            Self::FixedBvh4 => (
                cfg!(feature = "render-fixed"),
                cfg!(feature = "render-bvh4"),
            ),
        };
        mode && kind
    }
}

/// The caller's scene, its arrays as slices (valid for the call).
pub(super) struct View<'s> {
    pub(super) scene: RkScene,
    pub(super) objects: &'s [RkObject],
    pub(super) materials: &'s [RkMaterial],
    pub(super) lights: &'s [RkLight],
}

/// `count` values at `p` (null allowed when `count` is 0), checked for null and alignment.
///
/// # Safety
/// `p` is null or valid for reads of `count` values of `T` for `'s` (the caller's contract).
unsafe fn array<'s, T>(p: *const T, count: usize, fail: Failure) -> Result<&'s [T], Failure> {
    if count == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return Err(fail.with(RkStatus::ErrNull));
    }
    if !p.is_aligned() {
        return Err(fail.with(RkStatus::ErrMisaligned));
    }
    // SAFETY: non-null, aligned, valid for `count` reads (function contract).
    Ok(unsafe { core::slice::from_raw_parts(p, count) })
}

pub(super) fn view<'s>(scene: *const RkScene) -> Result<View<'s>, Failure> {
    if scene.is_null() {
        return Err(Failure::scene(RkStatus::ErrNull, "scene"));
    }
    // SAFETY: non-null, valid for reads (contract); every bit pattern is a valid `RkScene`.
    let scene = unsafe { scene.read() };
    let at = |field| Failure::scene(RkStatus::ErrNull, field);
    // SAFETY (all three): the arrays are valid for their counts during the call (contract).
    let objects = unsafe { array(scene.objects, scene.object_count as usize, at("objects")) }?;
    let materials = unsafe {
        array(
            scene.materials,
            scene.material_count as usize,
            at("materials"),
        )
    }?;
    let lights = unsafe { array(scene.lights, scene.light_count as usize, at("lights")) }?;
    Ok(View {
        scene,
        objects,
        materials,
        lights,
    })
}

/// How many of each thing a scene's memory holds.
#[derive(Clone, Copy, Debug)]
pub(super) struct Counts {
    pub(super) triangles: usize,
    pub(super) spheres: usize,
    pub(super) objects: usize,
    pub(super) materials: usize,
    pub(super) lights: usize,
    pub(super) accel: MemoryNeeded,
}

impl View<'_> {
    /// The mode and family; an unknown value is a bad argument, and so is a pair the crate's
    /// features leave out (named as the kind).
    pub(super) fn which(&self) -> Result<Which, Failure> {
        let bvh4 = self.bvh4()?;
        let which = match (self.scene.mode, bvh4) {
            (RK_MODE_F32, false) => Which::F32Bvh,
            (RK_MODE_F32, true) => Which::F32Bvh4,
            (RK_MODE_FIXED, false) => Which::FixedBvh,
            (RK_MODE_FIXED, true) => Which::FixedBvh4,
            _ => return Err(Failure::scene(RkStatus::ErrBadArgument, "mode")),
        };
        if !which.linked() {
            return Err(Failure::scene(RkStatus::ErrBadArgument, "kind"));
        }
        Ok(which)
    }

    /// Whether the scene names the 4-wide BVH (the default) rather than the binary one.
    fn bvh4(&self) -> Result<bool, Failure> {
        match self.scene.kind {
            0 | RK_KIND_BVH4 => Ok(true),
            RK_KIND_BVH => Ok(false),
            _ => Err(Failure::scene(RkStatus::ErrBadArgument, "kind")),
        }
    }

    /// The floats of object `o` (index `i`): nine per triangle or four per sphere.
    pub(super) fn data(&self, i: usize, o: &RkObject) -> Result<&[f32], Failure> {
        let per = match o.shape {
            RK_SHAPE_TRIANGLES => 9,
            RK_SHAPE_SPHERES => 4,
            _ => {
                return Err(Failure::new(
                    RkStatus::ErrBadArgument,
                    RK_ITEM_OBJECT,
                    i,
                    "shape",
                ))
            }
        };
        let Some(n) = (o.count as usize).checked_mul(per) else {
            return Err(Failure::new(
                RkStatus::ErrTooLarge,
                RK_ITEM_OBJECT,
                i,
                "count",
            ));
        };
        let fail = Failure::new(RkStatus::ErrNull, RK_ITEM_OBJECT, i, "data");
        // SAFETY: `data` is valid for `count` primitives during the call (contract).
        unsafe { array(o.data, n, fail) }
    }

    /// The counts, and the accelerator memory as the kernel's `memory_needed` gives it for a
    /// BVH (or 4-wide BVH) per object and a top-level BVH over two objects or more.
    pub(super) fn counts(&self) -> Result<Counts, Failure> {
        self.which()?;
        let bvh4 = self.bvh4()?;
        let (mut triangles, mut spheres, mut accel) = (0usize, 0usize, MemoryNeeded::NONE);
        let too_large = |i| Failure::new(RkStatus::ErrTooLarge, RK_ITEM_OBJECT, i, "count");
        for (i, o) in self.objects.iter().enumerate() {
            self.data(i, o)?;
            let n = o.count as usize;
            // The kernel refuses these too; refused here, the sizes below are the kernel's.
            if n > MAX_PRIMS {
                return Err(too_large(i));
            }
            let sum = if o.shape == RK_SHAPE_SPHERES {
                &mut spheres
            } else {
                &mut triangles
            };
            *sum = sum.checked_add(n).ok_or(too_large(i))?;
            let need = if bvh4 {
                MemoryNeeded::bvh4(n)
            } else {
                MemoryNeeded::bvh(n)
            };
            accel = accel.add(need);
        }
        if self.objects.len() >= 2 {
            accel = accel.add(MemoryNeeded::bvh(self.objects.len()));
        }
        Ok(Counts {
            triangles,
            spheres,
            objects: self.objects.len(),
            materials: self.materials.len(),
            lights: self.lights.len(),
            accel,
        })
    }
}
