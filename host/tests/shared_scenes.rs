//! The shared benchmark scenes (`../shared/scenes`, beside the workspace), when present:
//! every BVH builder, the grid and the kd-tree must give the same hits as brute force, byte for
//! byte, in both modes.

mod common;

use common::{bbox, random_rays, Camera, Rng};
use host::obj::load_obj;
use host::rayfile::encode_hits;
use host::trace::{trace, AccelKind, Mode, TraceConfig};
use raykernel::bvh::{BuildOptions, BuilderKind};
use std::path::PathBuf;

fn shared() -> Option<PathBuf> {
    let dir = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared"));
    dir.join("scenes/bunny.obj").exists().then_some(dir)
}

#[test]
fn bunny_bvh_matches_brute_force_for_every_builder_and_mode() {
    let Some(shared) = shared() else {
        println!("skipped: ../shared not found");
        return;
    };
    let scenes = shared.join("scenes");
    let obj = scenes.join("bunny.obj");
    let mesh = load_obj(&obj).unwrap();
    assert_eq!(mesh.triangle_count(), 69_630);

    // 1024 primary rays (a 32×32 subsample of the 1024² camera) and 1024 incoherent ones.
    let camera = Camera::parse(&std::fs::read_to_string(scenes.join("bunny.camera")).unwrap());
    let mut rays: Vec<_> = (0..32 * 32)
        .map(|i| camera.ray(32 * (i % 32) + 16, 32 * (i / 32) + 16, 1024))
        .collect();
    let (lo, hi) = bbox(&mesh.positions);
    rays.extend(random_rays(&mut Rng::new(0xB0_0B), lo, hi, 1024));

    for mode in [Mode::F32, Mode::Fixed] {
        let config = |accel, builder| TraceConfig {
            accel,
            build: BuildOptions {
                builder,
                max_leaf_size: 4,
            },
            mode,
            stride: 1,
            runs: 1,
            leaf_order: false,
        };
        let linear = trace(
            &mesh,
            &obj,
            &rays,
            &config(AccelKind::Linear, BuilderKind::Sah),
        )
        .unwrap();
        let hits = linear.stats.hits;
        assert!(hits > 600 && hits < 1900, "{mode:?}: {hits} hits");
        let reference = encode_hits(&linear.hits);
        for builder in BuilderKind::ALL {
            let bvh = trace(&mesh, &obj, &rays, &config(AccelKind::Bvh, builder)).unwrap();
            let differ: Vec<_> = (0..rays.len())
                .filter(|&i| bvh.hits[i] != linear.hits[i])
                .take(5)
                .map(|i| (i, rays[i], bvh.hits[i], linear.hits[i]))
                .collect();
            assert!(
                encode_hits(&bvh.hits) == reference,
                "{mode:?} {builder:?}: differs from linear, first (ray, bvh, linear): {differ:?}"
            );
        }
        for accel in [AccelKind::Grid, AccelKind::Kdtree] {
            let other = trace(&mesh, &obj, &rays, &config(accel, BuilderKind::Sah)).unwrap();
            assert!(
                encode_hits(&other.hits) == reference,
                "{mode:?} {accel:?}: differs from linear"
            );
        }
    }
}
