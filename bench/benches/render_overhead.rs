//! Criterion view of `raykernel_bench::overhead`: the renderer against hand-written casters doing
//! the same work (`primary`: no effect used, emissive objects, no lights; `shadow`: one point
//! light and shadow rays), single thread, 256×256, a 20,480-triangle icosphere on a floor.
//! `raykernel-bench` reports the same comparison as medians of interleaved runs.
//!
//! `cargo bench -p raykernel-bench --bench render_overhead`.

use criterion::{criterion_group, criterion_main, Criterion};
use raykernel::{Scalar, I16F16};
use raykernel_bench::overhead::{with_fixture, Workload, SIZE};

fn bench_mode<S: Scalar>(c: &mut Criterion) {
    let len = (3 * SIZE * SIZE) as usize;
    for workload in Workload::ALL {
        let mut group =
            c.benchmark_group(format!("render_overhead_{}_{}", workload.name(), S::NAME));
        group.sample_size(20);
        with_fixture::<S, _>(workload, |bare, render| {
            let mut out = vec![0u8; len];
            group.bench_function("bare_caster", |b| b.iter(|| bare(&mut out)));
            group.bench_function("renderer", |b| b.iter(|| render(&mut out)));
        });
        group.finish();
    }
}

fn benches(c: &mut Criterion) {
    bench_mode::<f32>(c);
    bench_mode::<I16F16>(c);
}

criterion_group!(overhead, benches);
criterion_main!(overhead);
