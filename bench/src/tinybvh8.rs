//! tinybvh's 8-wide CPU BVH (`BVH8_CPU`, tinybvh 1.6) as a peer of the interleaved rounds,
//! through the C++ shim in `csrc/tinybvh8_shim.cpp`, with the `tinybvh` feature. Its boxes
//! are tested in AVX2 lanes with fused multiply-subtract, its leaves hold four triangles that
//! one Möller–Trumbore test in SSE lanes (with an approximate reciprocal) checks at once, and
//! its children are pushed in an order precomputed per ray octant. Built by `Build` (binned
//! SAH) or `BuildHQ` (spatial splits), it traces rays built beforehand, one foreign call per
//! pass, so its figures pay no ray setup: they pair with ours on pre-built rays.
//!
//! `tinybvh-rs` builds `BVH8_CPU` but offers its query only to crates compiled for AVX2, which
//! the benchmark is not (its kernel picks its AVX2 copy at run time); the shim compiles the
//! same header with tinybvh-rs's flags instead. Foreign calls are this module's only `unsafe`.
#![allow(unsafe_code)]

use host::rayfile::{HitRecord, RayRecord};
use host::trace::millis;
use std::ffi::c_void;
use std::ptr::NonNull;
use std::time::Instant;

mod ffi {
    use std::ffi::c_void;

    extern "C" {
        pub fn rkb_tiny8_new(tris: *const f32, count: u32, hq: i32) -> *mut c_void;
        pub fn rkb_tiny8_set_rays(
            bvh: *mut c_void,
            origin: *const f32,
            dir: *const f32,
            t_max: *const f32,
            count: u32,
        );
        pub fn rkb_tiny8_trace(bvh: *mut c_void, t_out: *mut f32, prim_out: *mut u32);
        pub fn rkb_tiny8_free(bvh: *mut c_void);
    }
}

/// How the tree is built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Build {
    /// `BVH8_CPU::Build`: tinybvh's binned SAH BVH, leaves split to four, collapsed to 8-wide.
    Sah,
    /// `BVH8_CPU::BuildHQ`: the same from its SBVH (spatial splits).
    Spatial,
}

impl Build {
    /// Both, in the order the rounds trace them.
    pub const ALL: [Self; 2] = [Self::Sah, Self::Spatial];

    /// The report's name for the peer built this way.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Sah => "tinybvh 1.6 BVH8",
            Self::Spatial => "tinybvh 1.6 BVH8 HQ",
        }
    }
}

/// A built `BVH8_CPU` with its rays (set once, outside the timing) and the hits of the last
/// pass.
pub struct TinyBvh8 {
    raw: NonNull<c_void>,
    build: Build,
    t: Vec<f32>,
    prim: Vec<u32>,
}

impl TinyBvh8 {
    /// Builds over `tris` and sets one ray per record (tinybvh's `Ray` constructor: direction
    /// normalised, reciprocals; a hit must lie below the record's `t_max`). `None` for more
    /// triangles or records than tinybvh indexes (`u32`).
    #[must_use]
    pub fn new(tris: &[[[f32; 3]; 3]], records: &[RayRecord], build: Build) -> Option<Self> {
        let count = u32::try_from(tris.len()).ok()?;
        let rays = u32::try_from(records.len()).ok()?;
        let flat: Vec<f32> = tris.iter().flatten().flatten().copied().collect();
        // SAFETY: `flat` holds `9 * count` floats, which the shim copies before returning.
        let raw =
            unsafe { ffi::rkb_tiny8_new(flat.as_ptr(), count, i32::from(build == Build::Spatial)) };
        let bvh = Self {
            raw: NonNull::new(raw)?,
            build,
            t: vec![0.0; records.len()],
            prim: vec![0; records.len()],
        };
        let origin: Vec<f32> = records.iter().flat_map(|r| r.origin).collect();
        let dir: Vec<f32> = records.iter().flat_map(|r| r.dir).collect();
        let t_max: Vec<f32> = records.iter().map(|r| r.t_max).collect();
        // SAFETY: the BVH is live; the three arrays hold `3 * rays`, `3 * rays` and `rays`
        // floats, copied by the shim.
        unsafe {
            ffi::rkb_tiny8_set_rays(
                bvh.raw.as_ptr(),
                origin.as_ptr(),
                dir.as_ptr(),
                t_max.as_ptr(),
                rays,
            );
        }
        Some(bvh)
    }

    /// One closest-hit pass over the rays: its wall time, ms.
    pub fn trace(&mut self) -> f64 {
        let start = Instant::now();
        // SAFETY: the BVH is live and the two outputs hold one slot per ray set in `new`.
        unsafe {
            ffi::rkb_tiny8_trace(
                self.raw.as_ptr(),
                self.t.as_mut_ptr(),
                self.prim.as_mut_ptr(),
            )
        };
        millis(start)
    }

    /// How it was built.
    #[must_use]
    pub fn build(&self) -> Build {
        self.build
    }

    /// Rays per pass.
    #[must_use]
    pub fn rays(&self) -> usize {
        self.t.len()
    }

    /// The hits of the last pass ([`HitRecord::MISS`] where none).
    #[must_use]
    pub fn hits(&self) -> Vec<HitRecord> {
        self.t
            .iter()
            .zip(&self.prim)
            .map(|(&t, &prim)| {
                if prim == HitRecord::MISS.prim {
                    HitRecord::MISS
                } else {
                    HitRecord { t, prim }
                }
            })
            .collect()
    }
}

impl Drop for TinyBvh8 {
    fn drop(&mut self) {
        // SAFETY: the BVH is live and released once.
        unsafe { ffi::rkb_tiny8_free(self.raw.as_ptr()) }
    }
}
