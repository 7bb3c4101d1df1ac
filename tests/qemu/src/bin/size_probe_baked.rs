//! Size probe `traverse_baked`: load a baked binary BVH in place (every check) and trace one
//! ray for the closest and any hit, `f32`; no builder linked, no defmt, a spinning panic
//! handler. `cargo xtask size` reports its `.text`/`.rodata`.
#![no_std]
#![no_main]

use core::hint::black_box;
use cortex_m_rt::entry;
use raykernel::baked::load_bvh;
use raykernel::{Accel, Ray};

/// Stands in for a baked file in flash (the optimiser cannot see its contents).
#[repr(C, align(128))]
struct Baked([u8; 256]);
static BAKED: Baked = Baked([0; 256]);

#[entry]
fn main() -> ! {
    let bytes: &[u8] = black_box(&BAKED.0);
    if let Ok(bvh) = load_bvh::<f32>(bytes) {
        let (o, d) = black_box(([0.0f32; 3], [0.0f32, 0.0, 1.0]));
        if let Ok(ray) = Ray::from_f32(o, d, 0.0, f32::INFINITY) {
            black_box(bvh.intersect(&ray));
            black_box(bvh.occluded(&ray));
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
