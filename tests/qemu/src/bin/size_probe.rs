//! Size probe: build a BVH and trace rays, f32 triangles, nothing else (no defmt, no panic
//! machinery beyond a spinning handler). `cargo xtask size` reports its `.text`/`.rodata`.
#![no_std]
#![no_main]

use core::hint::black_box;
use cortex_m_rt::entry;
use raykernel::bvh::{nodes_needed, BuildOptions};
use raykernel::{Accel, Bvh, Node, Ray, Triangle};

const N: usize = 4;

#[entry]
fn main() -> ! {
    let tris: [Triangle<f32>; N] = black_box([Triangle { v: [[0.0; 3]; 3] }; N]);
    let mut nodes = [Node::<f32>::EMPTY; nodes_needed(N)];
    let mut ids = [0u32; N];
    let options = black_box(BuildOptions::default());
    if let Ok(bvh) = Bvh::build(&tris, &mut nodes, &mut ids, options) {
        let (o, d) = black_box(([0.0f32; 3], [0.0f32, 0.0, 1.0]));
        if let Ok(ray) = Ray::from_f32(o, d, 0.0, f32::INFINITY) {
            black_box(bvh.intersect(&ray));
        }
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
