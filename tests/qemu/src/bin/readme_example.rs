//! The embedded example of docs/EMBEDDED.md: the lines between the `README` markers are its code
//! block, word for word (`cargo xtask qemu` checks that, builds this for all three cores and
//! runs it under QEMU: it exits 0 when the ray hits the nearer triangle at t = 5).
#![no_std]
#![no_main]

use panic_halt as _;

// README begin
use cortex_m_rt::entry;
use raykernel::bvh::{nodes_needed, BuildOptions};
use raykernel::{Accel, Bvh, Node, Ray, Triangle};

const N: usize = 2; // triangles, known at compile time
static TRIS: [Triangle<f32>; N] = [
    Triangle {
        v: [[-1.0, -1.0, 5.0], [1.0, -1.0, 5.0], [0.0, 1.0, 5.0]],
    },
    Triangle {
        v: [[-1.0, -1.0, 9.0], [1.0, -1.0, 9.0], [0.0, 1.0, 9.0]],
    },
];

#[entry]
fn main() -> ! {
    // Static arenas (in .bss, not on the stack), sized by the kernel's const fn.
    let nodes =
        cortex_m::singleton!(: [Node<f32>; nodes_needed(N)] = [Node::EMPTY; nodes_needed(N)]);
    let ids = cortex_m::singleton!(: [u32; N] = [0; N]);
    let (Some(nodes), Some(ids)) = (nodes, ids) else {
        exit(2)
    };
    let Ok(bvh) = Bvh::build(&TRIS, nodes, ids, BuildOptions::default()) else {
        exit(3)
    };
    let Ok(ray) = Ray::<f32>::from_f32([0.0; 3], [0.0, 0.0, 1.0], 0.0, f32::INFINITY) else {
        exit(4)
    };
    match bvh.intersect(&ray) {
        Some(hit) if hit.prim == 0 && hit.t == 5.0 => exit(0), // nearer triangle, t = 5
        _ => exit(1),
    }
}
// README end

fn exit(code: i32) -> ! {
    semihosting::process::exit(code)
}

/// A fault exits with 101 instead of spinning until QEMU's timeout.
#[cortex_m_rt::exception]
unsafe fn HardFault(_: &cortex_m_rt::ExceptionFrame) -> ! {
    exit(101)
}
