//! Many objects against one: a scene of `N` objects of one sphere each, against one object
//! holding the same `N` spheres, rendered at 64×64 pixels and 1 spp with one point light,
//! single thread. The renderer's top-level BVH over its objects should make the per-ray cost
//! grow with the logarithm of the object count, so the two renders should take comparable
//! time; both must give the same bytes, and the same bytes as brute force (one object traced
//! by [`AccelKind::Linear`]).

use host::trace::{median, millis, NodeArena};
use raykernel::render::{
    memory_needed, Camera, Light, Material, Object, ObjectSlot, RenderMemory, Renderer, Scene,
    Settings, Shape,
};
use raykernel::{AccelKind, AnyFamily, Scalar, Sphere, I16F16};
use serde::Serialize;
use std::time::Instant;

/// Image side, pixels.
pub const SIZE: u32 = 64;
/// Spheres per row of the grid they stand in.
const ROW: usize = 320;
const RADIUS: f32 = 0.4;
const LIGHT: [f32; 3] = [160.0, 300.0, 160.0];
const INTENSITY: f32 = 90_000.0;
const BACKGROUND: [f32; 3] = [0.05, 0.1, 0.2];

/// One mode's comparison.
#[derive(Clone, Debug, Serialize)]
pub struct ObjectsRow {
    /// Spheres, each its own object on the many-objects side.
    pub spheres: usize,
    /// Number mode.
    pub mode: &'static str,
    /// Scene conversion and every build of the many-objects scene (top level included), ms.
    pub many_build_ms: f64,
    /// The same for the one object, ms.
    pub one_build_ms: f64,
    /// Median render time of the many-objects scene, ms.
    pub many_render_ms: f64,
    /// Median render time of the one object, ms.
    pub one_render_ms: f64,
    /// Median over the runs of many ÷ one render time, each run's pair timed back to back.
    pub render_ratio: f64,
    /// Bytes of the many-objects image that differ from the one object's.
    pub differing_bytes: usize,
    /// Bytes of the one object's image that differ from brute force's.
    pub differing_bytes_brute_force: usize,
}

/// The `n` spheres: a grid on the ground, rows of [`ROW`], one unit apart.
fn spheres<S: Scalar>(n: usize) -> Vec<Sphere<S>> {
    (0..n)
        .filter_map(|i| {
            let (x, z) = ((i % ROW) as f32 + 0.5, (i / ROW) as f32 + 0.5);
            let c = |v: f32| S::coord_from_f32(v).ok();
            Some(Sphere {
                center: [c(x)?, c(RADIUS)?, c(z)?],
                radius: c(RADIUS)?,
            })
        })
        .collect()
}

/// Looking down at the grid from its front edge.
fn camera(n: usize) -> Camera {
    let depth = n.div_ceil(ROW) as f32;
    Camera {
        eye: [ROW as f32 * 0.5, 120.0, -60.0],
        look_at: [ROW as f32 * 0.5, 0.0, depth * 0.5],
        up: [0.0, 1.0, 0.0],
        vfov_deg: 60.0,
        aperture_radius: 0.0,
        focus_distance: 1.0,
    }
}

/// A built renderer over `objects` with `accel`, handed to `f`; returns `f`'s result and the
/// build time, ms.
fn with_renderer<S: Scalar, R>(
    objects: &[Object<'_, S>],
    accel: AccelKind,
    f: impl FnOnce(&Renderer<'_, S>) -> R,
) -> (R, f64) {
    let materials = [Material::Diffuse { albedo: [0.7; 3] }];
    let lights = [Light::Point {
        position: LIGHT,
        intensity: [INTENSITY; 3],
    }];
    let n = objects.iter().map(|o| o.shape.len()).sum();
    let scene = Scene {
        objects,
        materials: &materials,
        lights: &lights,
        camera: camera(n),
        background: BACKGROUND,
    };
    let settings = Settings {
        width: SIZE,
        height: SIZE,
        spp: 1,
        ..Settings::default()
    };
    let start = Instant::now();
    let need = memory_needed::<S, AnyFamily>(scene.objects, &accel);
    let mut slots = vec![ObjectSlot::EMPTY; need.objects];
    let mut arena = NodeArena::<S>::sized(need.accel);
    let memory = RenderMemory {
        objects: &mut slots,
        accel: arena.memory(),
    };
    let renderer =
        Renderer::new(&scene, settings, accel, memory).expect("the objects scene is valid");
    let build_ms = millis(start);
    (f(&renderer), build_ms)
}

/// Renders into a fresh buffer; returns the bytes and the time, ms.
fn render<S: Scalar>(r: &Renderer<'_, S>) -> (Vec<u8>, f64) {
    let mut out = vec![0u8; 3 * (SIZE * SIZE) as usize];
    let start = Instant::now();
    r.render_srgb8(&mut out).expect("the buffer fits the image");
    let ms = millis(start);
    (out, ms)
}

fn differing(a: &[u8], b: &[u8]) -> usize {
    a.iter().zip(b).filter(|(x, y)| x != y).count() + a.len().abs_diff(b.len())
}

fn measure<S: Scalar>(mode: &'static str, n: usize, runs: usize) -> ObjectsRow {
    let spheres = spheres::<S>(n);
    let many: Vec<Object<'_, S>> = spheres
        .chunks(1)
        .map(|one| Object::new(Shape::Spheres(one), 0))
        .collect();
    let one = [Object::new(Shape::Spheres(&spheres), 0)];
    let accel = AccelKind::default();
    let (((many_image, one_image, times), one_build_ms), many_build_ms) =
        with_renderer(&many, accel, |rm| {
            with_renderer(&one, accel, |ro| {
                let (mut many_image, mut one_image) = (Vec::new(), Vec::new());
                let mut times = Vec::new();
                for _ in 0..runs.max(1) {
                    let (image, many_ms) = render(rm);
                    many_image = image;
                    let (image, one_ms) = render(ro);
                    one_image = image;
                    times.push((many_ms, one_ms));
                }
                (many_image, one_image, times)
            })
        });
    let (brute, _) = with_renderer(&one, AccelKind::Linear, |r| render(r).0);
    let ratios: Vec<f64> = times.iter().map(|(m, o)| m / o.max(1e-9)).collect();
    let many_ms: Vec<f64> = times.iter().map(|t| t.0).collect();
    let one_ms: Vec<f64> = times.iter().map(|t| t.1).collect();
    ObjectsRow {
        spheres: spheres.len(),
        mode,
        many_build_ms,
        one_build_ms,
        many_render_ms: median(&many_ms),
        one_render_ms: median(&one_ms),
        render_ratio: median(&ratios),
        differing_bytes: differing(&many_image, &one_image),
        differing_bytes_brute_force: differing(&one_image, &brute),
    }
}

/// Both modes with `n` spheres, `runs` interleaved render pairs each.
#[must_use]
pub fn run(n: usize, runs: usize) -> Vec<ObjectsRow> {
    eprintln!("bench: {n} one-sphere objects against one object");
    vec![
        measure::<f32>("f32", n, runs),
        measure::<I16F16>("fixed", n, runs),
    ]
}
