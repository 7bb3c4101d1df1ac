//! Criterion micro-benchmarks of the hot functions, so regressions show:
//! `slab/<mode>`, `triangle/<test>`, `build/bvh/icosphere5` and `trace/bvh/icosphere5`.
//! Each checks its answer once before timing (nothing is timed while giving wrong answers).
//!
//! `cargo bench -p raykernel-bench --bench hot` (criterion is a dev-dependency of the benchmark
//! only; the kernel has no dependency on it).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use raykernel::bvh::{nodes_needed, BuildOptions};
use raykernel::{Aabb, Accel, Bvh, Node, Ray, Scalar, Triangle, I16F16};
use raykernel_bench::mt::moller_trumbore;
use std::hint::black_box;

fn ray<S: Scalar>(o: [f32; 3], d: [f32; 3]) -> Ray<S> {
    Ray::<S>::from_f32(o, d, 0.0, f32::INFINITY).expect("a valid ray")
}

fn slab_in<S: Scalar>(c: &mut Criterion) {
    let b = Aabb::<S>::new(
        [-1.0, -1.0, 4.0].map(S::from_f32_saturating),
        [1.0, 1.0, 6.0].map(S::from_f32_saturating),
    );
    let r = ray::<S>([0.1, 0.2, 0.0], [0.05, -0.02, 1.0]);
    assert!(b.slab(&r).is_some(), "the benchmarked ray must hit the box");
    c.bench_function(&format!("slab/{}", S::NAME), |bench| {
        bench.iter(|| black_box(black_box(&b).slab(black_box(&r))));
    });
}

fn triangle_in<S: Scalar>(c: &mut Criterion) {
    let t = Triangle::<S>::from_f32([[-1.0, -1.0, 5.0], [1.0, -1.0, 5.0], [0.0, 1.0, 5.0]])
        .expect("valid vertices");
    let r = ray::<S>([0.1, 0.2, 0.0], [0.01, -0.02, 1.0]);
    assert!(
        t.intersect(&r).is_some(),
        "the benchmarked ray must hit the triangle"
    );
    c.bench_function(&format!("triangle/watertight-{}", S::NAME), |bench| {
        bench.iter(|| black_box(black_box(&t).intersect(black_box(&r))));
    });
}

fn slab(c: &mut Criterion) {
    slab_in::<f32>(c);
    slab_in::<I16F16>(c);
}

fn triangle(c: &mut Criterion) {
    triangle_in::<f32>(c);
    triangle_in::<I16F16>(c);
    let v = [[-1.0, -1.0, 5.0], [1.0, -1.0, 5.0], [0.0, 1.0, 5.0]];
    let (o, d) = ([0.1, 0.2, 0.0], [0.01, -0.02, 1.0]);
    assert!(moller_trumbore(&v, o, d, 0.0, f32::INFINITY).is_some());
    c.bench_function("triangle/moller-trumbore-f32", |bench| {
        bench.iter(|| {
            black_box(moller_trumbore(
                black_box(&v),
                black_box(o),
                black_box(d),
                0.0,
                f32::INFINITY,
            ))
        });
    });
}

/// An icosphere of 20,480 triangles (radius 1) and 1024 rays from points inside it.
fn scene() -> (Vec<Triangle<f32>>, Vec<Ray<f32>>) {
    let (p, faces) = raykernel_testkit::icosphere::unit_icosphere(5);
    let tris = faces
        .iter()
        .map(|f| {
            Triangle::from_f32(f.map(|i| p[i as usize].map(|x| x as f32)))
                .expect("vertices in range")
        })
        .collect();
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut unit = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f32 / (1u64 << 53) as f32
    };
    let rays = (0..1024)
        .map(|_| {
            let o = [0.0; 3].map(|_: f32| 0.5 * (unit() - 0.5));
            let d = [0.0; 3].map(|_: f32| unit() - 0.5);
            ray::<f32>(o, d)
        })
        .collect();
    (tris, rays)
}

fn bvh(c: &mut Criterion) {
    let (tris, rays) = scene();
    let mut nodes = vec![Node::<f32>::EMPTY; nodes_needed(tris.len())];
    let mut ids = vec![0u32; tris.len()];
    let mut group = c.benchmark_group("build/bvh");
    group.sample_size(20);
    group.throughput(Throughput::Elements(tris.len() as u64));
    group.bench_function("icosphere5", |bench| {
        bench.iter(|| {
            let built = Bvh::build(&tris, &mut nodes, &mut ids, BuildOptions::default());
            black_box(built.map(|b| b.depth()).ok())
        });
    });
    group.finish();
    let bvh = Bvh::build(&tris, &mut nodes, &mut ids, BuildOptions::default()).expect("builds");
    // From inside a closed sphere every ray hits, and the BVH agrees with brute force.
    let brute = raykernel::Linear::new(&tris);
    for r in &rays {
        let hit = bvh
            .intersect(r)
            .expect("a ray from inside a closed sphere hits");
        assert_eq!(Some(hit.prim), brute.intersect(r).map(|h| h.prim));
    }
    let mut group = c.benchmark_group("trace/bvh");
    group.throughput(Throughput::Elements(rays.len() as u64));
    group.bench_function("icosphere5", |bench| {
        bench.iter(|| {
            for r in &rays {
                black_box(bvh.intersect(black_box(r)));
            }
        });
    });
    group.finish();
}

criterion_group!(benches, slab, triangle, bvh);
criterion_main!(benches);
