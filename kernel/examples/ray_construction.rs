//! Cost of building `f32` rays: `Ray::<f32>::from_f32` over the rays of a ray file (32-byte
//! records `ox oy oz dx dy dz tmin tmax`, as `../shared/bench/make_rays.py` writes), repeated.
//!
//! `cargo run --release -p raykernel --example ray_construction -- FILE [REPEATS]` prints the
//! nanoseconds per ray of each repeat and a checksum of the rays' data (so nothing is optimised
//! away). Under `valgrind --tool=cachegrind` with two repeat counts, the difference of the
//! instruction counts divided by the rays built gives instructions per ray.

use raykernel::Ray;
use std::hint::black_box;
use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let Some(path) = args.next() else {
        eprintln!("usage: ray_construction FILE.rays [REPEATS]");
        std::process::exit(2);
    };
    let repeats: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(5);
    let bytes = std::fs::read(&path).unwrap_or_else(|e| {
        eprintln!("{path}: {e}");
        std::process::exit(1)
    });
    let f = |r: &[u8], i: usize| {
        f32::from_le_bytes([r[4 * i], r[4 * i + 1], r[4 * i + 2], r[4 * i + 3]])
    };
    let rays: Vec<([f32; 3], [f32; 3], f32, f32)> = bytes
        .chunks_exact(32)
        .map(|r| {
            (
                [f(r, 0), f(r, 1), f(r, 2)],
                [f(r, 3), f(r, 4), f(r, 5)],
                f(r, 6),
                f(r, 7),
            )
        })
        .collect();
    let mut checksum = 0u32;
    for _ in 0..repeats {
        let start = Instant::now();
        for &(o, d, t_min, t_max) in &rays {
            if let Ok(ray) = Ray::<f32>::from_f32(black_box(o), black_box(d), t_min, t_max) {
                let ray = black_box(ray);
                checksum = checksum.wrapping_add(ray.dir().x.to_bits());
            }
        }
        let ns = start.elapsed().as_nanos() as f64 / rays.len().max(1) as f64;
        println!("{} rays: {ns:.2} ns per ray", rays.len());
    }
    println!("checksum {checksum:#010x}");
}
