//! Panic-freedom check for the baked loader, as `panic_never.rs` does for the BVH: loads baked
//! bytes the optimiser cannot see (`black_box`) with every loader, in both modes, and calls
//! every query and accessor on what loads, linked with a panic handler that calls a function
//! nobody defines. Build: `cargo build --release --bin panic_never_baked --features
//! panic-check` in tests/qemu. Never run: it only has to link.
#![no_std]
#![no_main]

use core::hint::black_box;
use cortex_m_rt::entry;
use raykernel::baked::{load_bvh, load_bvh4, read_header, BakedScalar};
use raykernel::{Accel, Baked, Ray, TraversalStats, I16F16};

#[path = "../panic_check.rs"]
mod panic_check;

/// Stands in for a baked file in flash.
#[repr(C, align(128))]
struct Bytes([u8; 512]);
static BYTES: Bytes = Bytes([0; 512]);

fn exercise<S: BakedScalar>(bytes: &[u8]) {
    let (o, d, t0, t1) = black_box(([0.0f32; 3], [0.0f32, 0.0, 1.0], 0.0f32, 100.0f32));
    let Ok(ray) = Ray::<S>::from_f32(o, d, t0, t1) else {
        return;
    };
    let mut stats = TraversalStats::default();
    black_box(read_header(bytes).ok());
    if let Ok(t) = load_bvh::<S>(bytes) {
        black_box((t.intersect(&ray), t.occluded(&ray)));
        black_box(t.intersect_counted(&ray, &mut stats));
    }
    if let Ok(t) = load_bvh4::<S>(bytes) {
        black_box((t.intersect(&ray), t.occluded(&ray)));
        black_box(t.occluded_counted(&ray, &mut stats));
    }
    if let Ok(t) = Baked::<S>::load(bytes) {
        black_box((t.intersect(&ray), t.occluded(&ray)));
    }
    black_box(stats);
}

#[entry]
fn main() -> ! {
    let len = black_box(BYTES.0.len());
    let bytes = BYTES.0.get(..len).unwrap_or_default();
    exercise::<f32>(black_box(bytes));
    exercise::<I16F16>(black_box(bytes));
    loop {
        cortex_m::asm::wfi();
    }
}
