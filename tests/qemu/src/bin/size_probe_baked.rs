//! Size probe `traverse_baked`: load a baked binary BVH in place from flash (every check) and
//! trace rays for the closest and any hit, `f32`; no builder linked, no defmt, a spinning panic
//! handler. `cargo xtask size` reports its `.text`/`.rodata` (the baked file included) and runs
//! it under QEMU to measure its stack: the only measuring code is the store to [`PROBE_DONE`],
//! made only if the file loaded.
#![no_std]
#![no_main]

use core::hint::black_box;
use core::sync::atomic::{AtomicU32, Ordering};
use cortex_m_rt::entry;
use raykernel::baked::load_bvh;
use raykernel::{Accel, Ray};

/// The baked file in flash (`tests/golden/baked_ico.bvh`, written by host/tests/bake.rs),
/// aligned as the loader needs.
#[repr(C, align(128))]
struct Aligned<T: ?Sized>(T);
static BAKED: &Aligned<[u8]> = &Aligned(*include_bytes!("../../../golden/baked_ico.bvh"));

/// Set to `DONE` when the workload has run; `cargo xtask size` polls it (in .bss).
#[no_mangle]
static PROBE_DONE: AtomicU32 = AtomicU32::new(0);
/// "DONE", as `xtask/src/size.rs` expects.
const DONE: u32 = 0x444f_4e45;

/// The directions traced: a 4×4 fan around +z, at the mesh. A table in flash, as a firmware's
/// ray list would be, so the probe's own code is the loop over it.
static FAN: [[f32; 3]; 16] = fan();

const fn fan() -> [[f32; 3]; 16] {
    let mut dirs = [[0.0; 3]; 16];
    let mut k = 0;
    while k < 16 {
        let (x, y) = ((k % 4) as f32, (k / 4) as f32);
        dirs[k] = [x * 0.1 - 0.15, y * 0.1 - 0.15, 1.0];
        k += 1;
    }
    dirs
}

/// Loads the tree and traces the fan of rays; the hits go to `black_box`.
#[inline(never)]
fn load_and_trace() -> bool {
    // The optimiser cannot see the bytes, so the loader runs every check.
    let bytes: &[u8] = black_box(&BAKED.0);
    let Ok(bvh) = load_bvh::<f32>(bytes) else {
        return false;
    };
    let origin = black_box([0.1f32, 0.2, -5.0]);
    for &d in black_box(&FAN) {
        if let Ok(ray) = Ray::from_f32(origin, d, 0.0, f32::INFINITY) {
            black_box(bvh.intersect(&ray));
            black_box(bvh.occluded(&ray));
        }
    }
    true
}

#[entry]
fn main() -> ! {
    if load_and_trace() {
        PROBE_DONE.store(DONE, Ordering::Relaxed);
    }
    loop {
        cortex_m::asm::wfi();
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {
        cortex_m::asm::wfi();
    }
}
