//! `raykernel bake` and `raykernel trace-baked`: on a generated mesh (and on `../shared`'s suzanne when
//! present), in both modes and both trees, tracing the baked file gives hit files
//! byte-identical to `host trace` building the same tree in process; a corrupted file is
//! refused with the loader's error.

mod common;

use common::{random_rays, temp_dir, Rng};
use host::bake::{run_bake, run_trace_baked, BakeAccel, BakeArgs, TraceBakedArgs};
use host::cli::{run_trace, TraceArgs};
use host::rayfile::write_rays;
use host::trace::{Builder, Mode};
use raykernel::bvh::DEFAULT_LEAF_SIZE;
use raykernel::AccelKind;
use raykernel_testkit::icosphere::unit_icosphere;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// An icosphere OBJ (level 3, 1280 triangles, radius 1.2, jittered vertices) in `dir`.
fn generated_obj(dir: &Path) -> PathBuf {
    let (verts, faces) = unit_icosphere(3);
    let mut rng = Rng::new(0xBA4E);
    let mut text = String::new();
    for v in &verts {
        let r = 1.2 + 0.05 * rng.range_f64(-1.0, 1.0);
        writeln!(text, "v {} {} {}", v[0] * r, v[1] * r, v[2] * r).unwrap();
    }
    for f in &faces {
        writeln!(text, "f {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1).unwrap();
    }
    let path = dir.join("ico.obj");
    std::fs::write(&path, text).unwrap();
    path
}

fn check_scene(obj: &Path, rays: &Path, dir: &Path) {
    for mode in [Mode::F32, Mode::Fixed] {
        for (accel, kind) in [
            (BakeAccel::Bvh, AccelKind::Bvh(Default::default())),
            (BakeAccel::Bvh4, AccelKind::Bvh4(Default::default())),
        ] {
            let case = format!("{} {mode:?} {accel:?}", obj.display());
            let baked = dir.join("mesh.baked");
            let report = run_bake(&BakeArgs {
                scene: obj.to_path_buf(),
                out: baked.clone(),
                accel,
                mode,
                builder: Builder::Sah,
                leaf: DEFAULT_LEAF_SIZE,
                leaf_order: false,
            })
            .unwrap_or_else(|e| panic!("{case}: bake: {e}"));
            assert_eq!(
                report.bytes as u64,
                std::fs::metadata(&baked).unwrap().len()
            );
            let built_hits = dir.join("built.hits");
            let built = run_trace(&TraceArgs {
                scene: obj.to_path_buf(),
                rays: rays.to_path_buf(),
                out: built_hits.clone(),
                accel: kind,
                builder: Builder::Sah,
                mode,
                leaf: DEFAULT_LEAF_SIZE,
                no_reinsertion: false,
                stride: 1,
                runs: 1,
                leaf_order: false,
                coherent: false,
            })
            .unwrap_or_else(|e| panic!("{case}: trace: {e}"));
            let baked_hits = dir.join("baked.hits");
            let loaded = run_trace_baked(&TraceBakedArgs {
                baked: baked.clone(),
                rays: rays.to_path_buf(),
                out: baked_hits.clone(),
            })
            .unwrap_or_else(|e| panic!("{case}: trace-baked: {e}"));
            assert!(built.hits > 0, "{case}: no hits");
            assert_eq!(loaded.hits, built.hits, "{case}");
            assert_eq!(loaded.grid_hash, report.grid_hash, "{case}: grid hash");
            let (a, b) = (
                std::fs::read(&built_hits).unwrap(),
                std::fs::read(&baked_hits).unwrap(),
            );
            assert!(a == b, "{case}: baked hits differ from the built tree's");
            // One flipped byte: refused (checksum), nothing written.
            let mut bytes = std::fs::read(&baked).unwrap();
            let mid = bytes.len() / 2;
            bytes[mid] ^= 4;
            std::fs::write(&baked, &bytes).unwrap();
            let err = run_trace_baked(&TraceBakedArgs {
                baked,
                rays: rays.to_path_buf(),
                out: dir.join("never.hits"),
            })
            .unwrap_err();
            assert!(err.to_string().contains("checksum"), "{case}: {err}");
        }
    }
}

#[test]
fn baked_files_trace_like_the_built_trees_on_a_generated_mesh() {
    let dir = temp_dir("bake-generated");
    let obj = generated_obj(&dir);
    let rays = dir.join("rays.bin");
    write_rays(
        &rays,
        &random_rays(&mut Rng::new(5), [-1.3; 3], [1.3; 3], 4000),
    )
    .unwrap();
    check_scene(&obj, &rays, &dir);
}

#[test]
fn baked_files_trace_like_the_built_trees_on_suzanne() {
    let obj = PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../shared/scenes/suzanne.obj"
    ));
    if !obj.exists() {
        println!("skipped: ../shared/scenes/suzanne.obj not found");
        return;
    }
    let dir = temp_dir("bake-suzanne");
    let rays = dir.join("rays.bin");
    write_rays(
        &rays,
        &random_rays(&mut Rng::new(6), [-5.0, -3.6, -3.2], [5.0, 3.6, 3.1], 4000),
    )
    .unwrap();
    check_scene(&obj, &rays, &dir);
}

/// The on-target inputs: an undistorted icosphere (level 2, 320 triangles, radius 1.2) baked
/// as an f32 4-wide BVH (the on-target test) and as an f32 binary BVH (the `traverse_baked`
/// size probe), and their grid hash, which both trees give. The files are rewritten with
/// `BLESS=1`; otherwise they must equal what `raykernel bake` writes now.
#[test]
fn on_target_baked_mesh_is_what_host_bake_writes() {
    let dir = temp_dir("bake-golden");
    let (verts, faces) = unit_icosphere(2);
    let mut text = String::new();
    for v in &verts {
        writeln!(text, "v {} {} {}", v[0] * 1.2, v[1] * 1.2, v[2] * 1.2).unwrap();
    }
    for f in &faces {
        writeln!(text, "f {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1).unwrap();
    }
    let obj = dir.join("ico.obj");
    std::fs::write(&obj, text).unwrap();
    let golden = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/golden");
    let hash = golden.join("baked_ico.grid_hash");
    for (accel, name) in [
        (BakeAccel::Bvh4, "baked_ico.bvh4"),
        (BakeAccel::Bvh, "baked_ico.bvh"),
    ] {
        let out = dir.join(name);
        let report = run_bake(&BakeArgs {
            scene: obj.clone(),
            out: out.clone(),
            accel,
            mode: Mode::F32,
            builder: Builder::Sah,
            leaf: DEFAULT_LEAF_SIZE,
            leaf_order: false,
        })
        .unwrap();
        let file = golden.join(name);
        let bytes = std::fs::read(&out).unwrap();
        if std::env::var_os("BLESS").is_some() {
            std::fs::write(&file, &bytes).unwrap();
            std::fs::write(&hash, format!("{}\n", report.grid_hash)).unwrap();
        }
        assert!(
            std::fs::read(&file).unwrap_or_default() == bytes,
            "{} is stale: BLESS=1 cargo test -p raykernel-host --test bake",
            file.display()
        );
        let committed = std::fs::read_to_string(&hash).unwrap_or_default();
        assert_eq!(
            committed.trim(),
            report.grid_hash,
            "{} ({name})",
            hash.display()
        );
    }
}

/// The committed baked file, loaded in place as the firmware loads it, gives the committed
/// grid hash (the on-target test asserts the same on each Cortex-M core).
#[test]
fn committed_baked_file_loads_to_the_committed_grid_hash() {
    #[repr(C, align(128))]
    struct Aligned<T: ?Sized>(T);
    let golden = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/golden");
    let bytes = std::fs::read(golden.join("baked_ico.bvh4")).unwrap();
    let mut aligned = Box::new(Aligned([0u8; 1 << 16]));
    assert!(
        bytes.len() <= aligned.0.len(),
        "golden bake grew past the test buffer"
    );
    aligned.0[..bytes.len()].copy_from_slice(&bytes);
    let tree = raykernel::baked::load_bvh4::<f32>(&aligned.0[..bytes.len()]).unwrap();
    let committed = std::fs::read_to_string(golden.join("baked_ico.grid_hash")).unwrap();
    assert_eq!(
        format!("{:08x}", host::bake::grid_hash(&tree)),
        committed.trim()
    );
}
