//! `trace` end to end on a generated closed mesh: every BVH configuration must write the same
//! hit file, byte for byte, as brute force, in each mode.

mod common;

use common::{icosphere, random_rays, temp_dir, Rng};
use host::cli::{run_trace, TraceArgs, TraceReport};
use host::rayfile::{read_hits, write_rays};
use host::trace::{Builder, Mode};
use host::{HitRecord, RayRecord};
use raykernel::bvh::BuildOptions;
use raykernel::grid::GridOptions;
use raykernel::kdtree::KdOptions;
use raykernel::AccelKind;
use std::path::{Path, PathBuf};

const CENTER: [f64; 3] = [0.3, -0.2, 0.1];
const RADIUS: f64 = 2.0;

struct Scene {
    obj: PathBuf,
    rays: PathBuf,
    records: Vec<RayRecord>,
    dir: PathBuf,
    /// Rays (by index) that start inside the sphere and must hit it.
    inside: Vec<usize>,
    /// Rays (by index) that the kernel must reject.
    bad: Vec<usize>,
}

/// An icosphere (1280 triangles) and rays from inside and outside it, some aimed exactly at
/// vertices, some with finite intervals, two unusable.
fn scene(name: &str) -> Scene {
    let dir = temp_dir(name);
    let sphere = icosphere(CENTER, RADIUS, 3);
    let obj = dir.join("sphere.obj");
    std::fs::write(&obj, sphere.to_obj()).unwrap();

    let mut rng = Rng::new(0x5EED_0001);
    let c = CENTER.map(|x| x as f32);
    let mut rays = Vec::new();
    let mut inside = Vec::new();
    // From inside: random points within half the radius, random directions.
    for _ in 0..600 {
        let o = [0, 1, 2].map(|k| c[k] + rng.range_f64(-0.55, 0.55) as f32);
        inside.push(rays.len());
        rays.push(RayRecord::new(o, rng.direction()));
    }
    // From the centre straight at vertices (hardest case for watertightness).
    let verts = sphere.positions_f32();
    for _ in 0..300 {
        let v = verts[rng.below(verts.len())];
        inside.push(rays.len());
        rays.push(RayRecord::new(c, [0, 1, 2].map(|k| v[k] - c[k])));
    }
    // From outside (and some inside the box but outside the sphere): random.
    rays.extend(random_rays(&mut rng, [-6.0; 3], [6.0; 3], 900));
    // From outside, aimed at vertices: shared edges and vertices from the other side.
    for _ in 0..200 {
        let v = verts[rng.below(verts.len())];
        let o = [0, 1, 2].map(|k| c[k] + 5.0 * rng.direction()[k]);
        rays.push(RayRecord::new(o, [0, 1, 2].map(|k| v[k] - o[k])));
    }
    // Finite intervals that cut the sphere off or start past the near hit.
    for _ in 0..200 {
        let mut r = random_rays(&mut rng, [-4.0; 3], [4.0; 3], 1)[0];
        r.t_min = rng.range_f64(0.0, 3.0) as f32;
        r.t_max = r.t_min + rng.range_f64(0.0, 4.0) as f32;
        rays.push(r);
    }
    let bad = vec![rays.len(), rays.len() + 1, rays.len() + 2];
    rays.push(RayRecord::new(c, [0.0; 3])); // zero direction
    rays.push(RayRecord::new([f32::NAN, 0.0, 0.0], [1.0, 0.0, 0.0])); // NaN origin
    rays.push(RayRecord {
        t_min: 2.0,
        t_max: 1.0,
        ..RayRecord::new(c, [1.0, 0.0, 0.0])
    }); // empty interval
    let ray_path = dir.join("sphere.rays");
    write_rays(&ray_path, &rays).unwrap();
    Scene {
        obj,
        rays: ray_path,
        records: rays,
        dir,
        inside,
        bad,
    }
}

fn args(s: &Scene, accel: AccelKind, builder: Builder, mode: Mode, leaf: u32) -> TraceArgs {
    let out = s
        .dir
        .join(format!("{}.{builder:?}.{mode:?}.{leaf}.hits", accel.name()));
    TraceArgs {
        scene: s.obj.clone(),
        rays: s.rays.clone(),
        out,
        accel,
        builder,
        mode,
        leaf,
        no_reinsertion: false,
        stride: 1,
        runs: 1,
        leaf_order: false,
        coherent: false,
    }
}

fn run(a: &TraceArgs) -> (TraceReport, Vec<u8>) {
    let report = run_trace(a).unwrap_or_else(|e| panic!("{a:?}: {e}"));
    (report, std::fs::read(&a.out).unwrap())
}

fn hits(path: &Path) -> Vec<HitRecord> {
    read_hits(path).unwrap()
}

#[test]
fn every_bvh_configuration_matches_brute_force_byte_for_byte() {
    let s = scene("end_to_end_bvh_vs_linear");
    for mode in [Mode::F32, Mode::Fixed] {
        let linear = args(&s, AccelKind::Linear, Builder::Sah, mode, 4);
        let (report, reference) = run(&linear);
        assert_eq!(report.rays, report.rays_in_file);
        assert_eq!(report.bad_rays, s.bad.len(), "{mode:?}");
        assert_eq!((report.nodes, report.depth, report.build_ms), (0, 0, 0.0));
        assert_eq!(report.builder, None);

        let ref_hits = hits(&linear.out);
        for &i in &s.bad {
            assert_eq!(ref_hits[i], HitRecord::MISS, "{mode:?} bad ray {i}");
        }
        // The sphere is closed: every ray from inside hits it (watertightness).
        let leaks: Vec<_> = s
            .inside
            .iter()
            .filter(|&&i| !ref_hits[i].is_hit())
            .collect();
        assert!(leaks.is_empty(), "{mode:?}: rays {leaks:?} escape");
        assert!(report.hits > s.inside.len() + 200, "{mode:?}: {report:?}");

        for builder in [Builder::Sah, Builder::Median, Builder::Midpoint] {
            for leaf in [1, 4] {
                let a = args(
                    &s,
                    AccelKind::Bvh(BuildOptions::DEFAULT),
                    builder,
                    mode,
                    leaf,
                );
                let (report, bytes) = run(&a);
                if bytes != reference {
                    let got = hits(&a.out);
                    let first: Vec<_> = (0..got.len())
                        .filter(|&i| got[i] != ref_hits[i])
                        .take(3)
                        .map(|i| (i, s.records[i], got[i], ref_hits[i]))
                        .collect();
                    panic!(
                        "{mode:?} {builder:?} leaf {leaf}: hit file differs from linear; \
                         first (ray index, ray, bvh, linear): {first:?}"
                    );
                }
                assert_eq!(report.triangles, 1280);
                assert_eq!(report.bad_rays, s.bad.len());
                assert!(report.nodes > 0 && report.depth > 0 && report.bytes_per_tri > 0.0);
                assert_eq!(report.mode, if mode == Mode::F32 { "f32" } else { "fixed" });
            }
        }
    }
}

#[test]
fn grid_and_kdtree_match_brute_force_byte_for_byte() {
    let s = scene("end_to_end_grid_kdtree");
    for mode in [Mode::F32, Mode::Fixed] {
        let (_, reference) = run(&args(&s, AccelKind::Linear, Builder::Sah, mode, 4));
        for accel in [
            AccelKind::Grid(GridOptions::DEFAULT),
            AccelKind::KdTree(KdOptions::DEFAULT),
        ] {
            let a = args(&s, accel, Builder::Sah, mode, 4);
            let (report, bytes) = run(&a);
            assert!(
                bytes == reference,
                "{mode:?} {accel:?}: hit file differs from linear"
            );
            assert_eq!(report.accel, accel.name());
            assert!(report.nodes > 0 && report.bytes_per_tri > 0.0, "{report:?}");
        }
    }
}

#[test]
fn modes_agree_on_which_rays_hit_the_sphere() {
    let s = scene("end_to_end_modes");
    let trace = |mode| {
        let a = args(
            &s,
            AccelKind::Bvh(BuildOptions::DEFAULT),
            Builder::Sah,
            mode,
            4,
        );
        run(&a);
        hits(&a.out)
    };
    let c = host::compare::compare_hits(&trace(Mode::F32), &trace(Mode::Fixed), 1e-3);
    // Rays aimed at vertices and interval ends can legitimately flip between modes; the rest
    // must agree.
    assert!(c.t_agree_pct > 97.0, "{c:?}");
    assert!(c.hitmiss < 60, "{c:?}");
}

#[test]
fn stride_traces_every_kth_ray_and_matches_the_full_run() {
    let s = scene("end_to_end_stride");
    for accel in [AccelKind::Bvh(BuildOptions::DEFAULT), AccelKind::Linear] {
        let full = args(&s, accel, Builder::Median, Mode::F32, 4);
        run(&full);
        let all = hits(&full.out);
        for stride in [1, 7, 64, 100_000] {
            let mut a = full.clone();
            a.stride = stride;
            a.out = s.dir.join(format!("stride{stride}.{accel:?}.hits"));
            let (report, _) = run(&a);
            let want: Vec<_> = all.iter().copied().step_by(stride).collect();
            assert!(hits(&a.out) == want, "stride {stride} {accel:?}");
            assert_eq!(report.rays, want.len());
            assert_eq!(report.stride, stride);
        }
    }
}

#[test]
fn leaf_order_writes_the_same_hit_files() {
    let s = scene("end_to_end_leaf_order");
    for mode in [Mode::F32, Mode::Fixed] {
        for builder in [Builder::Sah, Builder::Median, Builder::Midpoint] {
            for leaf in [1, 4, 16] {
                let normal = args(
                    &s,
                    AccelKind::Bvh(BuildOptions::DEFAULT),
                    builder,
                    mode,
                    leaf,
                );
                let (normal_report, normal_bytes) = run(&normal);
                let mut a = normal.clone();
                a.leaf_order = true;
                a.out = s
                    .dir
                    .join(format!("leaf_order.{builder:?}.{mode:?}.{leaf}.hits"));
                let (report, bytes) = run(&a);
                assert!(
                    bytes == normal_bytes,
                    "{mode:?} {builder:?} leaf {leaf}: leaf-order hits differ"
                );
                assert!(report.leaf_order && !normal_report.leaf_order);
                // Same tree, only the primitives moved.
                assert_eq!(
                    (report.nodes, report.depth, report.hits),
                    (normal_report.nodes, normal_report.depth, normal_report.hits)
                );
            }
        }
    }
}

/// The 4-wide BVH writes the bytes brute force writes, for every builder and leaf size, in id
/// order and in leaf order, and counts only its own nodes and the ids.
#[test]
fn bvh4_matches_brute_force_byte_for_byte() {
    let s = scene("end_to_end_bvh4");
    for mode in [Mode::F32, Mode::Fixed] {
        let (_, reference) = run(&args(&s, AccelKind::Linear, Builder::Sah, mode, 4));
        for builder in [Builder::Sah, Builder::Median, Builder::Midpoint] {
            for leaf in [1, 4, 16] {
                for leaf_order in [false, true] {
                    let mut a = args(
                        &s,
                        AccelKind::Bvh4(BuildOptions::DEFAULT),
                        builder,
                        mode,
                        leaf,
                    );
                    a.leaf_order = leaf_order;
                    a.out = s.dir.join(format!(
                        "bvh4.{builder:?}.{mode:?}.{leaf}.{leaf_order}.hits"
                    ));
                    let (report, bytes) = run(&a);
                    assert!(
                        bytes == reference,
                        "{mode:?} {builder:?} leaf {leaf} leaf order {leaf_order}: bvh4 differs"
                    );
                    assert_eq!(report.accel, "bvh4");
                    let expected = (report.nodes * 128 + report.triangles * 4) as f64;
                    let got = report.bytes_per_tri * report.triangles as f64;
                    assert!((got - expected).abs() <= 1e-9 * expected, "{report:?}");
                }
            }
        }
    }
}

/// The 8-wide BVH writes the bytes brute force writes, by its default walk and by its walk for
/// coherent rays (`--coherent`), in leaf order and not, and the report says which walk ran.
#[test]
fn bvh8_matches_brute_force_by_both_walks() {
    let s = scene("end_to_end_bvh8");
    for mode in [Mode::F32, Mode::Fixed] {
        let (_, reference) = run(&args(&s, AccelKind::Linear, Builder::Sah, mode, 4));
        for coherent in [false, true] {
            for leaf_order in [false, true] {
                let mut a = args(
                    &s,
                    AccelKind::Bvh8(BuildOptions::DEFAULT),
                    Builder::Sah,
                    mode,
                    3,
                );
                a.leaf_order = leaf_order;
                a.coherent = coherent;
                a.out = s
                    .dir
                    .join(format!("bvh8.{mode:?}.{coherent}.{leaf_order}.hits"));
                let (report, bytes) = run(&a);
                assert!(
                    bytes == reference,
                    "{mode:?} coherent {coherent} leaf order {leaf_order}: bvh8 differs"
                );
                assert_eq!((report.accel, report.coherent), ("bvh8", coherent));
            }
        }
    }
}

#[test]
fn several_runs_report_medians_and_write_the_same_hits() {
    let s = scene("end_to_end_runs");
    for leaf_order in [false, true] {
        let mut one = args(
            &s,
            AccelKind::Bvh(BuildOptions::DEFAULT),
            Builder::Sah,
            Mode::Fixed,
            4,
        );
        one.leaf_order = leaf_order;
        let (_, once) = run(&one);
        let mut three = one.clone();
        three.runs = 3;
        three.out = s.dir.join(format!("runs3.{leaf_order}.hits"));
        let (report, bytes) = run(&three);
        assert!(bytes == once, "leaf_order {leaf_order}");
        assert_eq!(report.runs, 3);
        assert_eq!(report.build_ms_runs.len(), 3);
        assert_eq!(report.trace_ms_runs.len(), 3);
        assert_eq!(report.trace_ms, host::trace::median(&report.trace_ms_runs));
        assert_eq!(report.build_ms, host::trace::median(&report.build_ms_runs));
        assert_eq!(report.per_ray_ms_runs.len(), 3);
        assert_eq!(
            report.per_ray_ms,
            host::trace::median(&report.per_ray_ms_runs)
        );
        // The headline counts ray construction; the pre-built figure does not.
        let per_s = |ms: f64| report.rays as f64 / (ms / 1e3) / 1e6;
        let (want, prebuilt) = (per_s(report.per_ray_ms), per_s(report.trace_ms));
        assert!(
            (report.mrays_per_s - want).abs() <= 1e-9 * want,
            "{report:?}"
        );
        assert!(
            (report.mrays_per_s_prebuilt - prebuilt).abs() <= 1e-9 * prebuilt,
            "{report:?}"
        );
    }
    let mut linear = args(&s, AccelKind::Linear, Builder::Sah, Mode::F32, 4);
    linear.runs = 2;
    let (report, _) = run(&linear);
    assert_eq!((report.runs, report.build_ms), (2, 0.0));
}
