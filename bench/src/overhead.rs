//! The render plan's promise: unused features cost (almost) nothing. The renderer against
//! hand-written casters doing the same work on the same BVH, single thread, 256×256 pixels, a
//! level-5 icosphere (20,480 triangles) on a floor:
//!
//! - [`Workload::Primary`]: a scene that uses none of the distribution effects (1 spp,
//!   pinhole, static, no lights, no reflecting material: the objects are emissive) against a
//!   bare primary-ray caster (camera ray, closest hit, the hit object's colour or the
//!   background, sRGB encoding). The bound is 5%.
//! - [`Workload::Shadow`]: a diffuse material and one point light against a caster that also
//!   casts the shadow ray (the kernel's spawn rule) and shades Lambert.
//!
//! `raykernel-bench` reports medians of interleaved runs (the overhead as the median of each
//! run's ratio); `cargo bench -p raykernel-bench --bench render_overhead` measures the same
//! fixtures with criterion.

use host::trace::NodeArena;
use raykernel::bvh::{nodes_needed, BuildOptions};
use raykernel::glam::Vec3;
use raykernel::render::{
    encode_srgb8, Camera, Light, Material, Object, ObjectSlot, RenderMemory, Renderer, Scene,
    Settings, Shape,
};
use raykernel::spawn::spawn_shadow_ray;
use raykernel::{Accel, AccelKind, AccelMemory, Bvh, Ray, Scalar, Triangle, I16F16};
use serde::Serialize;
use std::hint::black_box;
use std::time::Instant;

/// Image side in pixels.
pub const SIZE: u32 = 256;
const ALBEDO: f32 = 0.7;
const LIGHT: [f32; 3] = [2.0, 4.0, 3.0];
const INTENSITY: f32 = 20.0;
/// Emitted radiance of the primary workload's objects, and its background.
const GLOW: [f32; 3] = [0.9, 0.6, 0.3];
const BACKGROUND: [f32; 3] = [0.05, 0.1, 0.2];
const CAMERA: Camera = Camera {
    eye: [0.0, 1.2, 3.5],
    look_at: [0.0, 0.6, 0.0],
    up: [0.0, 1.0, 0.0],
    vfov_deg: 40.0,
    aperture_radius: 0.0,
    focus_distance: 1.0,
};

/// Which comparison.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Workload {
    /// No effect used: camera rays and emissive surfaces.
    Primary,
    /// One point light: camera rays, shadow rays, Lambert shading.
    Shadow,
}

impl Workload {
    /// Both, in report order.
    pub const ALL: [Self; 2] = [Self::Primary, Self::Shadow];

    /// Name in reports.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Primary => "primary",
            Self::Shadow => "shadow",
        }
    }
}

/// The icosphere on its floor, in mode `S`.
fn geometry<S: Scalar>() -> Vec<Triangle<S>> {
    let (verts, faces) = raykernel_testkit::icosphere::unit_icosphere(5);
    let p = |i: u32| {
        let v = verts[i as usize];
        [
            v[0] as f32 * 0.6,
            v[1] as f32 * 0.6 + 0.6,
            v[2] as f32 * 0.6,
        ]
    };
    let mut t: Vec<[[f32; 3]; 3]> = faces.iter().map(|f| [p(f[0]), p(f[1]), p(f[2])]).collect();
    t.push([[-5.0, 0.0, -5.0], [-5.0, 0.0, 5.0], [5.0, 0.0, 5.0]]);
    t.push([[-5.0, 0.0, -5.0], [5.0, 0.0, 5.0], [5.0, 0.0, -5.0]]);
    t.iter()
        .filter_map(|v| Triangle::from_f32(*v).ok())
        .collect()
}

/// The camera's forward, right and up vectors, the half-height scaled: the renderer's model.
fn camera_frame() -> (Vec3, Vec3, Vec3) {
    let eye = Vec3::from_array(CAMERA.eye);
    let w = (Vec3::from_array(CAMERA.look_at) - eye).normalize();
    let right = w.cross(Vec3::from_array(CAMERA.up)).normalize();
    let up = right.cross(w);
    let h = (CAMERA.vfov_deg.to_radians() * 0.5).tan();
    (w, right * h, up * h)
}

/// Pixel `(x, y)`'s camera direction and its place in the output.
fn pixel_ray<S: Scalar>(x: u32, y: u32, frame: (Vec3, Vec3, Vec3)) -> (Option<Ray<S>>, Vec3) {
    let (w, u, v) = frame;
    let sx = 2.0 * (x as f32 + 0.5) / SIZE as f32 - 1.0;
    let sy = 1.0 - 2.0 * (y as f32 + 0.5) / SIZE as f32;
    let d = w + u * sx + v * sy;
    let ray = Ray::<S>::from_f32(CAMERA.eye, d.to_array(), 0.0, f32::INFINITY).ok();
    (ray, d)
}

fn write_rgb(out: &mut [u8], x: u32, y: u32, c: [f32; 3]) {
    let i = 3 * (y * SIZE + x) as usize;
    if let Some(px) = out.get_mut(i..i + 3) {
        for (o, c) in px.iter_mut().zip(c) {
            *o = encode_srgb8(c);
        }
    }
}

/// The bare primary-ray caster: camera ray, closest hit, the emitter's colour or the background.
///
/// Not inlined, like the renderer's tile loop: each is then one copy per mode in every binary,
/// and the comparison does not depend on how a caller's closure happened to be compiled.
#[inline(never)]
fn bare_primary<S: Scalar>(bvh: &Bvh<'_, S, Triangle<S>>, out: &mut [u8]) {
    let frame = camera_frame();
    for y in 0..SIZE {
        for x in 0..SIZE {
            let (ray, _) = pixel_ray::<S>(x, y, frame);
            let hit = ray.is_some_and(|r| bvh.intersect(&r).is_some());
            // Through `black_box`: a caster's colours come from its shading, so the compiler
            // must not pre-encode the two constants.
            write_rgb(out, x, y, black_box(if hit { GLOW } else { BACKGROUND }));
        }
    }
}

/// The bare shadow caster: camera ray, closest hit, one shadow ray by the kernel's spawn rule,
/// Lambert shading of a point light. Not inlined, as [`bare_primary`].
#[inline(never)]
fn bare_shadow<S: Scalar>(bvh: &Bvh<'_, S, Triangle<S>>, tris: &[Triangle<S>], out: &mut [u8]) {
    let frame = camera_frame();
    let light = LIGHT.map(|x| S::coord_from_f32(x).unwrap_or(S::ZERO));
    for y in 0..SIZE {
        for x in 0..SIZE {
            let (ray, d) = pixel_ray::<S>(x, y, frame);
            let mut c = 0.0f32;
            if let Some((ray, hit)) = ray.and_then(|r| bvh.intersect(&r).map(|h| (r, h))) {
                let tri = &tris[hit.prim as usize];
                let vf = tri.v.map(|p| Vec3::from_array(p.map(S::to_f32)));
                let mut n = (vf[1] - vf[0]).cross(vf[2] - vf[0]).normalize();
                if n.dot(d.normalize()) > 0.0 {
                    n = -n;
                }
                let (hu, hv) = (hit.u.to_f32(), hit.v.to_f32());
                let p = vf[0] + (vf[1] - vf[0]) * hu + (vf[2] - vf[0]) * hv;
                let to = Vec3::from_array(LIGHT) - p;
                let d2 = to.length_squared();
                let cos = n.dot(to) / d2.sqrt();
                if cos > 0.0 {
                    let lit = spawn_shadow_ray(&ray, &hit, tri, light)
                        .is_ok_and(|shadow| !bvh.occluded(&shadow));
                    if lit {
                        c = ALBEDO / std::f32::consts::PI * INTENSITY * cos / d2;
                    }
                }
            }
            write_rgb(out, x, y, black_box([c; 3]));
        }
    }
}

/// Builds both sides of `workload` in mode `S` and hands `f` the bare caster and the renderer,
/// each writing `3·SIZE²` sRGB bytes.
///
/// # Panics
/// If the fixed scene fails to build (it does not).
pub fn with_fixture<S: Scalar, R>(
    workload: Workload,
    f: impl FnOnce(&mut dyn FnMut(&mut [u8]), &mut dyn FnMut(&mut [u8])) -> R,
) -> R {
    let tris = geometry::<S>();
    // Both BVHs in 64-byte aligned arenas (a sibling pair per cache line), so that neither side
    // pays for where the allocator happened to put its nodes.
    let mut nodes = NodeArena::<S>::with_slots(nodes_needed(tris.len()));
    let mut ids = vec![0u32; tris.len()];
    let bvh = Bvh::build(&tris, nodes.slots(), &mut ids, BuildOptions::default())
        .expect("the overhead scene builds");
    let (material, lights, background) = match workload {
        Workload::Primary => (Material::Emissive { radiance: GLOW }, &[][..], BACKGROUND),
        Workload::Shadow => (
            Material::Diffuse {
                albedo: [ALBEDO; 3],
            },
            &[Light::Point {
                position: LIGHT,
                intensity: [INTENSITY; 3],
            }][..],
            [0.0; 3],
        ),
    };
    let objects = [Object::new(Shape::Triangles(&tris), 0)];
    let materials = [material];
    let scene = Scene {
        objects: &objects,
        materials: &materials,
        lights,
        camera: CAMERA,
        background,
    };
    let settings = Settings {
        width: SIZE,
        height: SIZE,
        spp: 1,
        ..Settings::default()
    };
    let mut nodes2 = NodeArena::<S>::with_slots(nodes_needed(tris.len()));
    let mut ids2 = vec![0u32; tris.len()];
    let mut slots = [ObjectSlot::<S>::EMPTY; 1];
    let memory = RenderMemory {
        objects: &mut slots,
        accel: AccelMemory {
            nodes: nodes2.slots(),
            words: &mut ids2,
            ..AccelMemory::default()
        },
    };
    let r = Renderer::new(&scene, settings, AccelKind::default(), memory)
        .expect("the overhead scene is valid");
    let p = r.plan();
    assert!(p.pixel_centre && !p.reflections && !p.lens && !p.motion && p.area_lights == 0);
    let mut bare = |out: &mut [u8]| match workload {
        Workload::Primary => bare_primary(black_box(&bvh), out),
        Workload::Shadow => bare_shadow(black_box(&bvh), &tris, out),
    };
    let mut render = |out: &mut [u8]| {
        let _ = r.render_srgb8(black_box(out));
    };
    f(&mut bare, &mut render)
}

/// One measured comparison.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OverheadRow {
    /// `primary` or `shadow`.
    pub workload: String,
    /// Number mode.
    pub mode: String,
    /// Median wall time of the bare caster, ms.
    pub bare_ms: f64,
    /// Median wall time of the renderer, ms.
    pub renderer_ms: f64,
    /// Median over the runs of `renderer / bare − 1`, each run's pair timed back to back,
    /// percent. (A ratio per pair cancels the machine's slow and fast spells, which a ratio of
    /// the two medians does not.)
    pub overhead_pct: f64,
    /// Bytes of the two images that differ (0: the same picture).
    pub differing_bytes: usize,
}

/// Medians of `runs` interleaved runs of each side, for every workload in both modes.
#[must_use]
pub fn run(runs: usize) -> Vec<OverheadRow> {
    let mut rows = Vec::new();
    for workload in Workload::ALL {
        rows.push(measure::<f32>(workload, runs));
        rows.push(measure::<I16F16>(workload, runs));
    }
    rows
}

fn measure<S: Scalar>(workload: Workload, runs: usize) -> OverheadRow {
    let len = (3 * SIZE * SIZE) as usize;
    let (mut a, mut b) = (vec![0u8; len], vec![0u8; len]);
    let (mut bare_ms, mut renderer_ms) = (Vec::new(), Vec::new());
    let time = |f: &mut dyn FnMut(&mut [u8]), out: &mut [u8]| {
        let start = Instant::now();
        f(out);
        start.elapsed().as_secs_f64() * 1e3
    };
    with_fixture::<S, _>(workload, |bare, render| {
        // One warm-up each, then alternate so drift affects both sides alike.
        bare(&mut a);
        render(&mut b);
        for _ in 0..runs.max(1) {
            bare_ms.push(time(bare, &mut a));
            renderer_ms.push(time(render, &mut b));
        }
    });
    let ratios: Vec<f64> = renderer_ms
        .iter()
        .zip(&bare_ms)
        .map(|(r, b)| r / b)
        .collect();
    OverheadRow {
        workload: workload.name().into(),
        mode: S::NAME.into(),
        bare_ms: host::trace::median(&bare_ms),
        renderer_ms: host::trace::median(&renderer_ms),
        overhead_pct: (host::trace::median(&ratios) - 1.0) * 100.0,
        differing_bytes: a.iter().zip(&b).filter(|(x, y)| x != y).count(),
    }
}
