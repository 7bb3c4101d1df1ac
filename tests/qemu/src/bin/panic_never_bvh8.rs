//! Panic-freedom check for the 8-wide BVH ([`raykernel::Bvh8`]): `panic_wide.rs`'s build,
//! collapse, queries, checker and accessors, in both modes, for triangles and spheres, linked
//! with a panic handler that calls a function nobody defines. Build: `cargo build --release
//! --bin panic_never_bvh8 --features panic-check` in tests/qemu (`cargo xtask panic-check`).
//! Never run: it only has to link.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use raykernel::bvh8::nodes8_needed;
use raykernel::{Node8, I16F16};

#[path = "../panic_wide.rs"]
mod panic_wide;
use panic_wide::{exercise, spheres, triangles, N};

#[entry]
fn main() -> ! {
    let mut wide = [Node8::<f32>::EMPTY; nodes8_needed(N)];
    exercise(&triangles::<f32>(), &mut wide);
    exercise(&spheres::<f32>(), &mut wide);
    let mut wide = [Node8::<I16F16>::EMPTY; nodes8_needed(N)];
    exercise(&triangles::<I16F16>(), &mut wide);
    exercise(&spheres::<I16F16>(), &mut wide);
    loop {
        cortex_m::asm::nop();
    }
}

#[path = "../panic_check.rs"]
mod panic_check;
