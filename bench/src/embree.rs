//! Embree 3 (the system's `libembree3`, Debian's `libembree-dev` 3.13) as a peer, through the
//! C shim in `csrc/embree_shim.c`: one device on one thread (`threads=1`), a triangle scene
//! built at [`Quality::High`] (SAH with spatial splits) or [`Quality::Medium`] (SAH), in
//! Embree's default mode or its robust one ([`Settings::robust`]), traced with one
//! `rtcIntersect1` (closest) or `rtcOccluded1` (any hit) call per ray record, with the
//! record's origin, direction, `tmin` and `tmax` as given. The call takes the raw record, so
//! Embree's figures include its ray setup, as our per-ray figures include ours.
//!
//! Memory is what Embree's device memory monitor reports for the scene: the bytes allocated
//! by the build, net of what the build freed (its structure; the vertex and index buffers are
//! ours, shared with Embree). Embree allocates in blocks, so this counts reserved blocks, not
//! only the bytes in use.
//!
//! Embree's AVX-512 and AVX2 kernels return with the upper halves of the vector registers in
//! use (no `vzeroupper`), and until something clears them every SSE instruction that follows
//! pays a merge: the next contender timed after Embree, ours included, ran markedly slower
//! than alone. So every call into Embree is followed, outside its timing, by
//! [`clear_upper_vector_state`], as compiled AVX code does before it returns to SSE code.
//!
//! The benchmark's `unsafe` code is here (the foreign calls, and the `vzeroupper`) and in
//! `tinybvh8` (its foreign calls).
#![allow(unsafe_code)]

use crate::workload::RayKind;
use host::obj::Mesh;
use host::rayfile::{HitRecord, RayRecord};
use host::trace::millis;
use std::ffi::c_void;
use std::ptr::NonNull;
use std::time::Instant;

mod ffi {
    use std::ffi::c_void;

    /// The shim's device (opaque).
    #[repr(C)]
    pub struct Device {
        _private: [u8; 0],
    }

    extern "C" {
        pub fn rkb_embree_new() -> *mut Device;
        pub fn rkb_embree_free(device: *mut Device);
        pub fn rkb_embree_bytes(device: *mut Device) -> i64;
        pub fn rkb_embree_peak(device: *const Device) -> i64;
        pub fn rkb_embree_build(
            device: *mut Device,
            vertices: *const f32,
            vertex_count: usize,
            indices: *const u32,
            tri_count: usize,
            quality: i32,
            robust: i32,
        ) -> *mut c_void;
        pub fn rkb_embree_scene_free(scene: *mut c_void);
        pub fn rkb_embree_closest(
            scene: *mut c_void,
            records: *const f32,
            count: usize,
            coherent: i32,
            t_out: *mut f32,
            prim_out: *mut u32,
        );
        pub fn rkb_embree_occluded(
            scene: *mut c_void,
            records: *const f32,
            count: usize,
            coherent: i32,
        ) -> usize;
    }
}

/// Embree's build quality (`RTC_BUILD_QUALITY_*`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quality {
    /// `RTC_BUILD_QUALITY_HIGH`: SAH with spatial splits.
    High,
    /// `RTC_BUILD_QUALITY_MEDIUM`: SAH, Embree's default.
    Medium,
}

impl Quality {
    fn raw(self) -> i32 {
        match self {
            Self::High => 2,
            Self::Medium => 1,
        }
    }
}

/// How a scene is built and traversed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Settings {
    /// Build quality.
    pub quality: Quality,
    /// `RTC_SCENE_FLAG_ROBUST`: Embree's robust traversal, without the optimisations that
    /// reduce arithmetic accuracy (its answer to rays slipping through shared edges; its
    /// documentation does not promise watertightness).
    pub robust: bool,
}

impl Settings {
    /// `RTC_BUILD_QUALITY_HIGH`, default mode: the headline's peer.
    pub const HIGH: Self = Self {
        quality: Quality::High,
        robust: false,
    };
    /// `RTC_BUILD_QUALITY_MEDIUM`, default mode.
    pub const MEDIUM: Self = Self {
        quality: Quality::Medium,
        robust: false,
    };
    /// `RTC_BUILD_QUALITY_HIGH` in robust mode: the closest Embree comes to our guarantees.
    /// (Its build takes MEDIUM's time and bytes: the robust mode drops the spatial splits.)
    pub const HIGH_ROBUST: Self = Self {
        quality: Quality::High,
        robust: true,
    };
}

/// A device that builds and traces on one thread.
pub struct Device(NonNull<ffi::Device>);

impl Device {
    /// A new device (`None` if Embree cannot make one, e.g. a CPU it does not support).
    #[must_use]
    pub fn new() -> Option<Self> {
        // SAFETY: no arguments; a null result is handled.
        NonNull::new(unsafe { ffi::rkb_embree_new() }).map(Self)
    }

    /// Bytes Embree has allocated on this device now, net of frees; resets the peak. (`&self`:
    /// the counters live on the C side, behind the pointer; the device is not `Sync`.)
    fn bytes(&self) -> i64 {
        // SAFETY: the pointer is a live device (owned by `self`).
        unsafe { ffi::rkb_embree_bytes(self.0.as_ptr()) }
    }

    /// The largest allocation total since the last [`Device::bytes`].
    fn peak(&self) -> i64 {
        // SAFETY: as above.
        unsafe { ffi::rkb_embree_peak(self.0.as_ptr()) }
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: the device is live and dropped once; every scene borrowed it and is gone.
        unsafe { ffi::rkb_embree_free(self.0.as_ptr()) }
    }
}

/// The triangles as Embree reads them: positions (one spare float at the end, as Embree reads
/// 16 bytes per vertex) and three indices per triangle, in our triangle order.
pub struct Geometry {
    vertices: Vec<f32>,
    vertex_count: usize,
    indices: Vec<u32>,
}

impl Geometry {
    /// The mesh's positions and triangles, as given.
    #[must_use]
    pub fn of(mesh: &Mesh) -> Self {
        let mut vertices: Vec<f32> = mesh.positions.iter().flatten().copied().collect();
        vertices.push(0.0);
        Self {
            vertices,
            vertex_count: mesh.positions.len(),
            indices: mesh.triangles.iter().flatten().copied().collect(),
        }
    }

    /// Triangles.
    #[must_use]
    pub fn triangles(&self) -> usize {
        self.indices.len() / 3
    }
}

/// A built scene over a [`Geometry`] it borrows.
pub struct Scene<'d> {
    raw: NonNull<c_void>,
    _device: &'d Device,
    _geometry: &'d Geometry,
}

/// Figures of one build.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Built {
    /// Wall time of the build call (scene, geometry, commit).
    pub build_ms: f64,
    /// Bytes the build left allocated (the structure).
    pub bytes: usize,
    /// Most bytes allocated at once during the build.
    pub peak_bytes: usize,
}

impl<'d> Scene<'d> {
    /// Builds a scene over `geometry` with `settings` (timed). `None` if Embree reports an
    /// error.
    pub fn build(
        device: &'d Device,
        geometry: &'d Geometry,
        settings: Settings,
    ) -> Option<(Self, Built)> {
        let before = device.bytes();
        let start = Instant::now();
        // SAFETY: the device is live; the buffers hold `vertex_count` vertices (plus the
        // spare float) and `triangles()` index triples, and outlive the scene (borrowed
        // for 'd).
        let raw = unsafe {
            ffi::rkb_embree_build(
                device.0.as_ptr(),
                geometry.vertices.as_ptr(),
                geometry.vertex_count,
                geometry.indices.as_ptr(),
                geometry.triangles(),
                settings.quality.raw(),
                i32::from(settings.robust),
            )
        };
        let build_ms = millis(start);
        clear_upper_vector_state();
        let raw = NonNull::new(raw)?;
        let peak = device.peak();
        let after = device.bytes();
        let built = Built {
            build_ms,
            bytes: usize::try_from(after - before).unwrap_or(0),
            peak_bytes: usize::try_from(peak.max(after) - before).unwrap_or(0),
        };
        Some((
            Self {
                raw,
                _device: device,
                _geometry: geometry,
            },
            built,
        ))
    }

    /// Closest hit of every record (one `rtcIntersect1` each, timed) and the loop's wall
    /// time, ms. `records` is [`flat_records`] of a ray set of `kind`: primary rays are traced
    /// with Embree's coherent flag (`coherent_flag`).
    #[must_use]
    pub fn closest(&self, records: &[f32], kind: RayKind) -> (Vec<HitRecord>, f64) {
        let count = records.len() / 8;
        let mut t = vec![f32::INFINITY; count];
        let mut prim = vec![u32::MAX; count];
        let start = Instant::now();
        // SAFETY: the scene is live; `records` holds `count` 8-float records; the outputs
        // hold one slot per record.
        unsafe {
            ffi::rkb_embree_closest(
                self.raw.as_ptr(),
                records.as_ptr(),
                count,
                coherent_flag(kind),
                t.as_mut_ptr(),
                prim.as_mut_ptr(),
            );
        }
        let ms = millis(start);
        clear_upper_vector_state();
        let hits = t
            .into_iter()
            .zip(prim)
            .map(|(t, prim)| {
                if prim == u32::MAX {
                    HitRecord::MISS
                } else {
                    HitRecord { t, prim }
                }
            })
            .collect();
        (hits, ms)
    }

    /// Any hit of every record (one `rtcOccluded1` each, timed): how many are occluded, and
    /// the loop's wall time, ms. Flags as in [`Scene::closest`].
    #[must_use]
    pub fn occluded(&self, records: &[f32], kind: RayKind) -> (usize, f64) {
        let start = Instant::now();
        // SAFETY: as in `closest`.
        let n = unsafe {
            ffi::rkb_embree_occluded(
                self.raw.as_ptr(),
                records.as_ptr(),
                records.len() / 8,
                coherent_flag(kind),
            )
        };
        let ms = millis(start);
        clear_upper_vector_state();
        (n, ms)
    }
}

impl Drop for Scene<'_> {
    fn drop(&mut self) {
        // SAFETY: the scene is live and released once.
        unsafe { ffi::rkb_embree_scene_free(self.raw.as_ptr()) }
    }
}

/// The shim's `coherent` argument for a ray set: Embree's `RTC_INTERSECT_CONTEXT_FLAG_COHERENT`
/// for primary rays (as ours are traced through `raykernel::Coherent` in the contender that
/// names that walk), its default incoherent flag otherwise.
fn coherent_flag(kind: RayKind) -> i32 {
    i32::from(kind == RayKind::Primary)
}

/// The records as Embree's shim reads them: 8 floats each (origin, direction, tmin, tmax),
/// the ray file's layout.
#[must_use]
pub fn flat_records(records: &[RayRecord]) -> Vec<f32> {
    records
        .iter()
        .flat_map(|r| {
            [
                r.origin[0],
                r.origin[1],
                r.origin[2],
                r.dir[0],
                r.dir[1],
                r.dir[2],
                r.t_min,
                r.t_max,
            ]
        })
        .collect()
}

/// Clears the upper halves of the vector registers (`vzeroupper`) where the CPU has AVX, after
/// Embree's code has run (see the module documentation).
fn clear_upper_vector_state() {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the CPU has AVX (checked just above), which is all `vzeroupper` needs.
        unsafe { zero_upper() }
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn zero_upper() {
    std::arch::x86_64::_mm256_zeroupper();
}
