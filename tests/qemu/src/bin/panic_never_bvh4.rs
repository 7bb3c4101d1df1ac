//! Panic-freedom check for the 4-wide BVH ([`raykernel::Bvh4`]): `panic_wide.rs`'s build,
//! collapse, queries, checker and accessors, in both modes, for triangles and spheres, linked
//! with a panic handler that calls a function nobody defines. Build: `cargo build --release
//! --bin panic_never_bvh4 --features panic-check` in tests/qemu (`cargo xtask panic-check`).
//! Never run: it only has to link.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use raykernel::bvh4::nodes4_needed;
use raykernel::{Node4, I16F16};

#[path = "../panic_wide.rs"]
mod panic_wide;
use panic_wide::{exercise, spheres, triangles, N};

#[entry]
fn main() -> ! {
    let mut wide = [Node4::<f32>::EMPTY; nodes4_needed(N)];
    exercise(&triangles::<f32>(), &mut wide);
    exercise(&spheres::<f32>(), &mut wide);
    let mut wide = [Node4::<I16F16>::EMPTY; nodes4_needed(N)];
    exercise(&triangles::<I16F16>(), &mut wide);
    exercise(&spheres::<I16F16>(), &mut wide);
    loop {
        cortex_m::asm::nop();
    }
}

#[path = "../panic_check.rs"]
mod panic_check;
