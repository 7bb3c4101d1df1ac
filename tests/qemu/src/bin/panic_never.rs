//! Panic-freedom check: calls every public build and query entry point of the kernel, in both
//! modes, on inputs the optimiser cannot see (`black_box`), and links with a panic handler
//! that calls a function nobody defines. If any panic path stays reachable after
//! optimisation, the release link fails with
//! `undefined symbol: kernel_has_a_reachable_panic_path` and names the caller.
//! Build: `cargo build --release --bin panic_never` in tests/qemu (`cargo xtask panic-check`).
//! Never run: it only has to link.
#![no_std]
#![no_main]

use core::hint::black_box;
use cortex_m_rt::entry;
use raykernel::bvh::{nodes_needed, BuildOptions};
use raykernel::spawn::{spawn_ray, spawn_shadow_ray};
use raykernel::{
    Aabb, Accel, Bvh, Linear, Node, Primitive, Ray, Scalar, Sphere, TraversalStats, Triangle,
    Vec3x, I16F16,
};

const N: usize = 8;

/// Every query on every accelerator over `prims`, and the tree checks.
fn queries<S: Scalar, P: Primitive<S>>(bvh: &Bvh<'_, S, P>, prims: &[P], ray: &Ray<S>) {
    let mut stats = TraversalStats::default();
    black_box(bvh.intersect(ray));
    black_box(bvh.occluded(ray));
    black_box(bvh.intersect_counted(ray, &mut stats));
    black_box(bvh.occluded_counted(ray, &mut stats));
    black_box(bvh.validate().ok());
    black_box((
        bvh.bytes_used(),
        bvh.depth(),
        bvh.prim(black_box(3)).is_some(),
    ));
    black_box((bvh.nodes().len(), bvh.prim_ids().len(), bvh.prims().len()));
    let linear = Linear::new(prims);
    black_box(linear.intersect(ray));
    black_box(linear.occluded(ray));
    black_box(linear.intersect_counted(ray, &mut stats));
    black_box(linear.occluded_counted(ray, &mut stats));
    black_box(stats);
}

/// Secondary rays from a hit: reflection-style and shadow rays.
fn spawns<S: Scalar>(tri: &Triangle<S>, ray: &Ray<S>) {
    if let Some(hit) = tri.intersect(ray).map(|h| raykernel::Hit {
        t: h.t,
        prim: 0,
        u: h.u,
        v: h.v,
    }) {
        black_box(spawn_ray(ray, &hit, tri, ray.dir()).ok());
        black_box(spawn_shadow_ray(ray, &hit, tri, black_box([S::ZERO; 3])).ok());
    }
}

/// Rays from every constructor, then builds with both build entry points and queries.
fn exercise<S: Scalar, P: Primitive<S> + Copy>(prims: &mut [P; N], options: BuildOptions) {
    let (o, d, t0, t1) = black_box(([0.0f32; 3], [0.0f32, 0.0, 1.0], 0.0f32, 100.0f32));
    let Ok(ray) = Ray::<S>::from_f32(o, d, t0, t1) else {
        return;
    };
    let ray2 = Ray::<S>::new(ray.origin(), ray.dir()).and_then(|r| {
        let (a, b) = black_box((S::ZERO, S::FAR));
        r.with_interval(a, b)
    });
    let ray = ray2.unwrap_or(ray);
    let bx = Aabb::<S>::new(black_box([S::ZERO; 3]), black_box([S::FAR; 3]));
    black_box(bx.slab(&ray));
    black_box(bx.union(&prims[0].bounds()).contains(&bx));
    let count = black_box(N);
    let mut nodes = [Node::<S>::EMPTY; nodes_needed(N)];
    let mut ids = [0u32; N];
    let used = nodes_needed(count).min(N * 2);
    if let Ok(bvh) = Bvh::build(&prims[..], &mut nodes[..used], &mut ids, options) {
        queries(&bvh, &prims[..], &ray);
    }
    let mut nodes = [Node::<S>::EMPTY; nodes_needed(N)];
    let mut ids = [0u32; N];
    let mut copy = *prims;
    if let Ok(bvh) = Bvh::build_in_leaf_order(&mut copy[..], &mut nodes, &mut ids, options) {
        let mut stats = TraversalStats::default();
        black_box(bvh.intersect(&ray));
        black_box(bvh.occluded_counted(&ray, &mut stats));
        black_box(bvh.validate().ok());
    }
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
    let options = black_box(BuildOptions::default());
    exercise::<f32, _>(&mut triangles::<f32>(), options);
    exercise::<I16F16, _>(&mut triangles::<I16F16>(), options);
    exercise::<f32, _>(&mut spheres::<f32>(), options);
    exercise::<I16F16, _>(&mut spheres::<I16F16>(), options);

    // Direct constructors and single-primitive tests.
    let v = black_box([glam_vec(1.0), glam_vec(2.0), glam_vec(3.0)]);
    let t = Triangle::<f32>::new(v[0], v[1], v[2]);
    let s = Sphere::<f32>::new(v[0], black_box(1.0));
    if let Ok(r) = Ray::<f32>::new(v[0], v[1]) {
        black_box(t.intersect(&r));
        black_box(s.hit_t(r.data(), 0.0, f32::INFINITY));
    }
    let x = black_box([Vec3x::from_f32([1.0, 2.0, 3.0]); 3]);
    let tx = Triangle::<I16F16>::new(x[0], x[1], x[2]);
    let sx = Sphere::<I16F16>::new(x[0], black_box(I16F16::ONE));
    if let Ok(r) = Ray::<I16F16>::new(x[1], x[2]) {
        black_box(tx.intersect(&r));
        black_box(sx.hit_t(r.data(), I16F16::ZERO, I16F16::MAX));
    }
    black_box(x[0].to_f32());
    if let (Ok(r), Ok(rx)) = (Ray::<f32>::new(v[2], v[0]), Ray::<I16F16>::new(x[2], x[0])) {
        spawns(&t, &r);
        spawns(&tx, &rx);
    }

    // I16F16 arithmetic.
    let (a, b) = black_box((I16F16::from_f32(1.5), I16F16::from_raw(-7)));
    black_box((
        a + b,
        a - b,
        a * b,
        a / b,
        -a,
        a.to_f32(),
        I16F16::from_int(black_box(3)),
    ));
    black_box((a.raw(), a.min_of(b), a.max_of(b)));
    loop {
        cortex_m::asm::nop();
    }
}

fn glam_vec(x: f32) -> raykernel::glam::Vec3 {
    raykernel::glam::Vec3::new(x, -x, 0.5 * x)
}

#[path = "../panic_check.rs"]
mod panic_check;
