//! Panic-freedom check for the 4-wide BVH, as `panic_never.rs` does for the BVH: builds a BVH
//! and collapses it ([`raykernel::Bvh4::collapse`], into an arena of opaque length) and calls
//! every query, the checker and the accessors, in both modes, for triangles and spheres, on
//! inputs the optimiser cannot see (`black_box`), and links with a panic handler that calls a
//! function nobody defines. Build: `cargo build --release --bin panic_never_bvh4 --features
//! panic-check` in tests/qemu (`cargo xtask panic-check`). Never run: it only has to link.
#![no_std]
#![no_main]

use core::hint::black_box;
use cortex_m_rt::entry;
use raykernel::bvh::{nodes_needed, BuildOptions};
use raykernel::bvh4::nodes4_needed;
use raykernel::{
    Accel, Bvh, Bvh4, Node, Node4, Primitive, Ray, Scalar, Sphere, TraversalStats, Triangle, I16F16,
};

const N: usize = 8;

/// BVH build, collapse into an arena of opaque length, every query, the checker, accessors.
fn exercise<S: Scalar, P: Primitive<S>>(prims: &[P]) {
    let (o, d, t0, t1) = black_box(([0.0f32; 3], [0.0f32, 0.0, 1.0], 0.0f32, 100.0f32));
    let Ok(ray) = Ray::<S>::from_f32(o, d, t0, t1) else {
        return;
    };
    let mut stats = TraversalStats::default();
    let mut nodes = [Node::<S>::EMPTY; nodes_needed(N)];
    let mut ids = [0u32; N];
    let mut wide = [Node4::<S>::EMPTY; nodes4_needed(N)];
    let used = black_box(nodes4_needed(N)).min(wide.len());
    let options = black_box(BuildOptions::default());
    let Ok(bvh) = Bvh::build(prims, &mut nodes, &mut ids, options) else {
        return;
    };
    if let Ok(tree) = Bvh4::collapse(&bvh, &mut wide[..used]) {
        black_box(tree.intersect(&ray));
        black_box(tree.occluded(&ray));
        black_box(tree.intersect_counted(&ray, &mut stats));
        black_box(tree.occluded_counted(&ray, &mut stats));
        black_box(tree.validate().ok());
        black_box((tree.bytes_used(), tree.depth(), tree.is_leaf_order()));
        black_box((
            tree.nodes().len(),
            tree.prim_ids().len(),
            tree.prims().len(),
        ));
        if let Some(n) = tree.nodes().first() {
            let i = black_box(0usize);
            black_box((n.child_count(), n.bounds(i), n.slot(i)));
        }
    }
    black_box(stats);
}

fn triangles<S: Scalar>() -> [Triangle<S>; N] {
    let v: [[[f32; 3]; 3]; N] = black_box([[[0.0; 3]; 3]; N]);
    let mut out = [Triangle {
        v: [[S::ZERO; 3]; 3],
    }; N];
    for (o, v) in out.iter_mut().zip(v) {
        if let Ok(t) = Triangle::from_f32(v) {
            *o = t;
        }
    }
    out
}

fn spheres<S: Scalar>() -> [Sphere<S>; N] {
    let c: [([f32; 3], f32); N] = black_box([([0.0; 3], 1.0); N]);
    c.map(|(c, r)| Sphere {
        center: c.map(S::from_f32_saturating),
        radius: S::from_f32_saturating(r),
    })
}

#[entry]
fn main() -> ! {
    exercise::<f32, _>(&triangles::<f32>());
    exercise::<I16F16, _>(&triangles::<I16F16>());
    exercise::<f32, _>(&spheres::<f32>());
    exercise::<I16F16, _>(&spheres::<I16F16>());
    loop {
        cortex_m::asm::nop();
    }
}

#[path = "../panic_check.rs"]
mod panic_check;
