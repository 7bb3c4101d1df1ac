//! Cost of rendering the default scene (`scenes::CORNELL` at its own settings, `f32`, the BVH
//! family), single-threaded, repeated.
//!
//! `cargo run --release -p raykernel --example render_cost -- [REPEATS]` prints the
//! nanoseconds per pixel of each repeat and a checksum of the image. Under
//! `valgrind --tool=cachegrind` with two repeat counts, the difference of the instruction
//! counts divided by the extra pixels gives instructions per pixel (scene setup cancels out).

use raykernel::bvh::{nodes_needed, BuildOptions};
use raykernel::render::scenes;
use raykernel::render::{Object, ObjectSlot, RenderMemory, Renderer, Shape};
use raykernel::{AccelMemory, BvhFamily, Node, Sphere, Triangle};
use std::hint::black_box;
use std::time::Instant;

fn main() {
    let repeats: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(3);
    let data = scenes::CORNELL;
    let mut tris = vec![Triangle::<f32> { v: [[0.0; 3]; 3] }; data.triangles.len()];
    let mut spheres = vec![
        Sphere::<f32> {
            center: [0.0; 3],
            radius: 0.0
        };
        data.spheres.len()
    ];
    data.triangles_into(&mut tris).unwrap();
    data.spheres_into(&mut spheres).unwrap();
    let mut objects = vec![Object::new(Shape::Triangles(&[]), 0); data.objects.len()];
    let scene = data.scene(&tris, &spheres, &mut objects).unwrap();
    let n = data.objects.len();
    let mut slots = vec![ObjectSlot::<f32, BvhFamily>::EMPTY; n];
    let mut nodes =
        vec![Node::<f32>::EMPTY; nodes_needed(tris.len()) + nodes_needed(spheres.len()) + 4 * n];
    let mut ids = vec![0u32; tris.len() + spheres.len() + n];
    let memory = RenderMemory {
        objects: &mut slots,
        accel: AccelMemory {
            nodes: &mut nodes,
            words: &mut ids,
            ..AccelMemory::default()
        },
    };
    let r = Renderer::new(&scene, data.settings, BuildOptions::default(), memory).unwrap();
    let (w, h) = (data.settings.width, data.settings.height);
    let mut out = vec![0u8; (3 * w * h) as usize];
    let mut checksum = 0u64;
    for _ in 0..repeats {
        let start = Instant::now();
        r.render_srgb8(black_box(&mut out)).unwrap();
        let ns = start.elapsed().as_nanos() as f64 / f64::from(w * h);
        checksum = out.iter().fold(checksum, |c, &b| {
            c.wrapping_mul(31).wrapping_add(u64::from(b))
        });
        println!("{ns:.0} ns/pixel");
    }
    println!("checksum {checksum:#018x}");
}
