//! The renderer's top-level BVH at scale: `N` one-sphere objects (default 100,000) against one
//! object holding the same spheres, 64×64 at 1 spp with one point light, BVH per object. Prints
//! the time of each (build and render, single-threaded, best of three) and their ratio, and
//! checks that both images are the same bytes as brute force over the one object.
//!
//! `cargo run --release -p raykernel-host --example many_objects [-- N]`

use raykernel::bvh::BuildOptions;
use raykernel::render::{
    memory_needed, Camera, Light, Material, Object, ObjectSlot, RenderMemory, Renderer, Scene,
    Settings, Shape,
};
use raykernel::{AccelFamily, AccelMemory, BvhFamily, LinearFamily, Node, Sphere};
use raykernel_testkit::Rng;
use std::time::Instant;

const SIZE: u32 = 64;

fn spheres(n: usize) -> Vec<Sphere<f32>> {
    // Seeded, so every run and platform scatters the same spheres.
    let mut rng = Rng::new(0x5EED);
    let mut unit = || rng.unit();
    let side = (n as f32).cbrt();
    (0..n)
        .map(|_| {
            let c = [
                side * (unit() - 0.5),
                side * (unit() - 0.5),
                side * (1.0 + unit()),
            ];
            Sphere {
                center: c,
                radius: 0.1 + 0.3 * unit(),
            }
        })
        .collect()
}

/// Milliseconds of `Renderer::new` plus the render, and the sRGB bytes.
fn render<F: AccelFamily<f32>>(objects: &[Object<'_, f32>], options: F::Options) -> (f64, Vec<u8>) {
    let side = (objects.iter().map(|o| o.shape.len()).sum::<usize>() as f32).cbrt();
    let materials = [Material::Diffuse {
        albedo: [0.8, 0.7, 0.6],
    }];
    let lights = [Light::Point {
        position: [side, side, 0.0],
        intensity: [side * side * 4.0; 3],
    }];
    let scene = Scene {
        objects,
        materials: &materials,
        lights: &lights,
        camera: Camera {
            eye: [0.0, 0.0, -side * 0.5],
            look_at: [0.0, 0.0, side],
            up: [0.0, 1.0, 0.0],
            vfov_deg: 60.0,
            aperture_radius: 0.0,
            focus_distance: side,
        },
        background: [0.1, 0.1, 0.2],
    };
    let settings = Settings {
        width: SIZE,
        height: SIZE,
        spp: 1,
        ..Settings::default()
    };
    let need = memory_needed::<f32, F>(objects, &options);
    let mut nodes = vec![Node::<f32>::EMPTY; need.accel.nodes];
    let mut words = vec![0u32; need.accel.words];
    // Leaked: generic over `F`, a vector of slots borrowing from itself for the renderer's
    // lifetime could not be dropped (a named family's slots can live in a vector).
    let slots = Vec::leak(vec![ObjectSlot::<f32, F>::EMPTY; need.objects]);
    let mut out = vec![0u8; 3 * (SIZE * SIZE) as usize];
    let start = Instant::now();
    let memory = RenderMemory {
        objects: slots,
        accel: AccelMemory {
            nodes: &mut nodes,
            words: &mut words,
            ..AccelMemory::default()
        },
    };
    let r: Renderer<'_, f32, F> =
        Renderer::new(&scene, settings, options, memory).expect("the scene is valid");
    r.render_srgb8(&mut out).expect("the buffer fits");
    (start.elapsed().as_secs_f64() * 1e3, out)
}

fn best_of_three<F: AccelFamily<f32>>(
    objects: &[Object<'_, f32>],
    options: F::Options,
) -> (f64, Vec<u8>) {
    let (mut best, image) = render::<F>(objects, options);
    for _ in 0..2 {
        best = best.min(render::<F>(objects, options).0);
    }
    (best, image)
}

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map_or(100_000, |a| a.parse().expect("N: a number of spheres"));
    let all = spheres(n);
    let many: Vec<Object<'_, f32>> = all
        .iter()
        .map(|s| Object::new(Shape::Spheres(std::slice::from_ref(s)), 0))
        .collect();
    let one = [Object::new(Shape::Spheres(&all), 0)];
    let options = BuildOptions::default();
    let (ms_many, image_many) = best_of_three::<BvhFamily>(&many, options);
    let (ms_one, image_one) = best_of_three::<BvhFamily>(&one, options);
    let (_, brute) = render::<LinearFamily>(&one, ());
    assert!(image_many == brute, "{n} objects differ from brute force");
    assert!(image_one == brute, "one object differs from brute force");
    println!(
        "{n} one-sphere objects: {ms_many:.1} ms; one object of {n} spheres: {ms_one:.1} ms; \
         ratio {:.2}; both images equal brute force",
        ms_many / ms_one
    );
}
