//! Size probe `build_traverse`: an `f32` SAH BVH (no reinsertion) built over a small generated mesh, then
//! closest-hit and any-hit queries; nothing else (no defmt, a spinning panic handler).
//! `cargo xtask size` reports its `.text`/`.rodata` and runs it under QEMU to measure its stack:
//! the only measuring code is the store to [`PROBE_DONE`] once the workload has run.
#![no_std]
#![no_main]

use core::hint::black_box;
use core::sync::atomic::{AtomicU32, Ordering};
use cortex_m_rt::entry;
use raykernel::bvh::{nodes_needed, Sah, StaticBuild};
use raykernel::{Accel, Bvh, Node, Ray, Triangle};

/// Cells per side of the generated heightfield; two triangles per cell.
const GRID: usize = 4;
const N: usize = 2 * GRID * GRID;

/// Set to `DONE` when the workload has run; `cargo xtask size` polls it (in .bss).
#[no_mangle]
static PROBE_DONE: AtomicU32 = AtomicU32::new(0);
/// "DONE", as `xtask/src/size.rs` expects.
const DONE: u32 = 0x444f_4e45;

/// Builds the BVH and traces one ray at each grid vertex; the hits go to `black_box`.
#[inline(never)]
fn build_and_trace() {
    // Heights from a table the optimiser cannot see, so the build does real splits.
    let h = black_box([0.0f32, 1.0, 0.5, 2.0]);
    let p = |i: usize, j: usize| [i as f32, j as f32, h[(i + 2 * j) & 3]];
    let mut tris = [Triangle { v: [[0.0f32; 3]; 3] }; N];
    for (k, pair) in tris.chunks_exact_mut(2).enumerate() {
        let (i, j) = (k % GRID, k / GRID);
        pair[0].v = [p(i, j), p(i + 1, j), p(i, j + 1)];
        pair[1].v = [p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)];
    }
    let mut nodes = [Node::<f32>::EMPTY; nodes_needed(N)];
    let mut ids = [0u32; N];
    // SAH without the reinsertion pass, named at compile time: no other builder linked.
    let options = black_box(StaticBuild::<Sah, false>::default());
    let Ok(bvh) = Bvh::build(&tris, &mut nodes, &mut ids, options) else {
        return;
    };
    let origin = black_box([1.5f32, 2.5, 10.0]);
    for i in 0..=GRID {
        for j in 0..=GRID {
            let d = [i as f32 - origin[0], j as f32 - origin[1], -origin[2]];
            if let Ok(ray) = Ray::from_f32(origin, d, 0.0, f32::INFINITY) {
                black_box(bvh.intersect(&ray));
                black_box(bvh.occluded(&ray));
            }
        }
    }
}

#[entry]
fn main() -> ! {
    build_and_trace();
    PROBE_DONE.store(DONE, Ordering::Relaxed);
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
