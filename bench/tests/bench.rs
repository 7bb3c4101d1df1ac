//! `raykernel-bench` end to end on tiny generated scenes (no `../shared` needed): the report,
//! CSV, JSON and plots are written and well-formed. No timing is checked, only structure and
//! the figures that do not depend on time (hit counts, agreement, accuracy), read from
//! `data.json`'s figure rows.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A fresh, empty directory under the integration tests' temp dir.
fn temp_dir(name: &str) -> PathBuf {
    raykernel_testkit::empty_dir(Path::new(env!("CARGO_TARGET_TMPDIR")).join(name))
}

/// An icosphere of `20·4^levels` triangles around `center` as OBJ text.
fn icosphere_obj(center: [f64; 3], levels: u32) -> String {
    let (unit, triangles) = raykernel_testkit::icosphere::unit_icosphere(levels);
    let mut s = String::from("# icosphere\n");
    for v in unit {
        let p: [f32; 3] = std::array::from_fn(|k| (center[k] + v[k]) as f32);
        s += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for t in triangles {
        s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}

/// Two scenes (icospheres of 320 and 1280 triangles) with cameras in a fresh directory.
fn scenes(name: &str) -> PathBuf {
    let dir = temp_dir(name);
    for (scene, levels) in [("ball", 2), ("fine", 3)] {
        std::fs::write(
            dir.join(format!("{scene}.obj")),
            icosphere_obj([0.25, -0.5, 0.0], levels),
        )
        .unwrap();
        std::fs::write(
            dir.join(format!("{scene}.camera")),
            "# test camera\neye 0.3 0.2 4\ntarget 0.25 -0.5 0\nup 0 1 0\nvfov 50\n",
        )
        .unwrap();
    }
    dir
}

fn run_bench(scenes: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_raykernel-bench"))
        .arg("--scenes")
        .arg(scenes)
        .args(["--scene", "ball", "--scene", "fine", "--no-city"])
        .args([
            "--rust-rays",
            "--rays-per-set",
            "1024",
            "--runs",
            "1",
            "--rounds",
            "3",
        ])
        .args(["--scale", "500,2000", "--scale-rays", "256"])
        .args(["--image-spp", "4", "--objects", "2000"])
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .expect("run the benchmark binary")
}

/// The value of one figure row (panics if absent or repeated: rows are unique).
fn figure(rows: &[Value], scene: &str, rays: &str, contender: &str, name: &str) -> f64 {
    let found: Vec<&Value> = rows
        .iter()
        .filter(|r| {
            r["scene"] == scene
                && r["rays"] == rays
                && r["contender"] == contender
                && r["figure"] == name
        })
        .collect();
    assert_eq!(
        found.len(),
        1,
        "figure {scene} {rays} {contender} {name}: {found:?}"
    );
    found[0]["value"].as_f64().unwrap()
}

#[test]
fn bench_writes_a_well_formed_report_csv_json_and_plots() {
    let dir = scenes("bench_report");
    let out = dir.join("out");
    let output = run_bench(&dir, &out, &[]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "raykernel-bench failed: {stderr}");

    // The last stdout line is the JSON summary naming the files.
    let stdout = String::from_utf8_lossy(&output.stdout);
    let summary: Value = serde_json::from_str(stdout.lines().last().unwrap()).unwrap();
    assert_eq!(
        summary["report"],
        out.join("BENCHMARKS.md").display().to_string()
    );

    // Report: the machine line first and the command; tables not ragged.
    let report = std::fs::read_to_string(out.join("BENCHMARKS.md")).unwrap();
    let mut lines = report.lines();
    assert_eq!(lines.next(), Some("# Benchmarks"));
    assert_eq!(lines.next(), Some(""));
    let machine = lines.next().unwrap();
    assert!(
        machine.starts_with("machine: ") && machine.contains("cores; rustc"),
        "{machine}"
    );
    assert!(report.contains("- command: `raykernel-bench --scenes"));
    let mut cells = None;
    for line in report.lines() {
        if line.starts_with('|') {
            let n = line.matches('|').count();
            match cells {
                None => cells = Some(n),
                Some(m) => assert_eq!(n, m, "ragged table row: {line}"),
            }
        } else {
            cells = None;
        }
    }

    // data.json: one row per (scene, rays, contender, figure), unique, finite.
    let json: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("data.json")).unwrap()).unwrap();
    let rows = json["figures"].as_array().unwrap();
    let mut keys = std::collections::BTreeSet::new();
    for r in rows {
        let key =
            ["scene", "rays", "contender", "figure"].map(|k| r[k].as_str().unwrap().to_owned());
        assert!(r["value"].as_f64().unwrap().is_finite(), "{r}");
        assert!(keys.insert(key), "repeated figure row {r}");
    }
    assert_eq!(summary["figures"].as_u64().unwrap() as usize, rows.len());

    // The CSV holds the same rows.
    let csv = std::fs::read_to_string(out.join("data.csv")).unwrap();
    let mut csv_lines = csv.lines();
    assert_eq!(csv_lines.next(), Some("scene,rays,contender,figure,value"));
    assert_eq!(csv_lines.count(), rows.len());

    let peers = raykernel_bench::peers::Peer::ALL;
    let mut ours = vec![
        "raykernel bvh4 sah f32",
        "raykernel bvh4 sah fixed",
        "raykernel bvh8 sah f32",
        "raykernel bvh8 sah fixed",
        "raykernel bvh sah f32",
        "raykernel bvh sah fixed",
        "raykernel bvh sah f32 MT",
        "raykernel bvh median f32",
        "raykernel bvh midpoint fixed",
        "raykernel grid - f32",
        "raykernel kdtree - fixed",
    ];
    ours.sort_unstable();
    for scene in ["ball", "fine"] {
        for rays in ["primary", "incoherent"] {
            let traced = figure(rows, scene, rays, "f64 reference", "rays");
            assert_eq!(traced, 1024.0);
            for contender in &ours {
                // Every contender finds the reference's hits on a closed sphere: no leaks, no
                // invented hits; both per-ray and pre-built figures are there.
                for name in ["leaks", "false_hits"] {
                    assert_eq!(figure(rows, scene, rays, contender, name), 0.0);
                }
                for name in ["closest_mrays", "closest_mrays_prebuilt", "any_mrays"] {
                    assert!(figure(rows, scene, rays, contender, name) > 0.0);
                }
                assert!(figure(rows, scene, rays, contender, "setup_ns_per_ray") > 0.0);
            }
            for peer in peers {
                let name = peer.name();
                assert_eq!(figure(rows, scene, rays, name, "hitmiss_vs_ours"), 0.0);
                assert_eq!(figure(rows, scene, rays, name, "only_peer_hits"), 0.0);
                assert!(figure(rows, scene, rays, name, "closest_mrays") > 0.0);
                assert!(figure(rows, scene, rays, name, "agree_pct_vs_ours") > 99.0);
                // Embree takes raw records: no pre-built figure.
                let prebuilt = rows.iter().any(|r| {
                    r["scene"] == scene
                        && r["rays"] == rays
                        && r["contender"] == name
                        && r["figure"] == "closest_mrays_prebuilt"
                });
                assert_eq!(prebuilt, !peer.is_embree(), "{name}");
            }
            // The headline row names the faster wide BVH of this ray set.
            let headline = report.lines().any(|l| {
                l.starts_with(&format!("| {scene} | "))
                    && ["bvh4", "bvh8"]
                        .iter()
                        .any(|s| l.contains(&format!("| {rays} | {s} | ")))
            });
            assert!(headline, "no headline row for {scene} {rays}");
            // Interleaved rounds: three of each wide BVH each way, and of each peer in this
            // build.
            for k in 1..=3 {
                for ours in ["raykernel bvh4 sah f32", "raykernel bvh8 sah f32"] {
                    let name = format!("closest_mrays_round{k}");
                    assert!(figure(rows, scene, rays, ours, &name) > 0.0);
                    let prebuilt = format!("closest_mrays_prebuilt_round{k}");
                    assert!(figure(rows, scene, rays, ours, &prebuilt) > 0.0);
                }
                if peers.iter().any(|p| p.is_embree()) {
                    let name = format!("closest_mrays_round{k}");
                    for embree in ["Embree 3 HIGH", "Embree 3 HIGH robust"] {
                        assert!(figure(rows, scene, rays, embree, &name) > 0.0, "{embree}");
                    }
                }
                if cfg!(feature = "tinybvh") {
                    let name = format!("closest_mrays_prebuilt_round{k}");
                    for tiny in ["tinybvh 1.6 BVH8", "tinybvh 1.6 BVH8 HQ"] {
                        assert!(figure(rows, scene, rays, tiny, &name) > 0.0, "{tiny}");
                    }
                }
            }
            // tinybvh's 8-wide BVH finds ours' triangles (not watertight: a few may differ).
            if cfg!(feature = "tinybvh") {
                for tiny in ["tinybvh 1.6 BVH8", "tinybvh 1.6 BVH8 HQ"] {
                    let same = figure(rows, scene, rays, tiny, "same_prim_pct_vs_ours");
                    assert!(same > 99.0, "{tiny}: {same}% of hits as ours");
                }
            }
        }
    }

    // Scale: two sizes × two modes, the exact instance triangle counts plus the ground.
    let scale = json["scale"].as_array().unwrap();
    assert_eq!(scale.len(), 4);
    assert!(scale[0]["triangles"].as_u64().unwrap() >= 500);

    // Objects: 2,000 one-sphere objects render the bytes of one object holding them, and of
    // brute force, in both modes.
    for mode in ["f32", "fixed"] {
        let contender = format!("raykernel render objects {mode}");
        for name in ["differing_bytes", "differing_bytes_brute_force"] {
            assert_eq!(figure(rows, "spheres-2000", "-", &contender, name), 0.0);
        }
        for name in ["many_render_ms", "one_render_ms", "render_ratio"] {
            assert!(figure(rows, "spheres-2000", "-", &contender, name) > 0.0);
        }
    }
    assert!(report.contains("## Objects: many one-sphere objects"));

    // Refit: both scenes in both modes after small and large motion; the refitted tree gives
    // the rebuilt tree's hits.
    for scene in ["ball", "fine"] {
        for contender in ["f32 1%", "fixed 1%", "f32 10%", "fixed 10%"] {
            let contender = format!("raykernel refit {contender}");
            assert_eq!(
                figure(rows, scene, "primary", &contender, "differing_hits"),
                0.0
            );
            for name in ["rebuild_ms", "refit_bvh_ms", "refit_bvh4_ms"] {
                assert!(figure(rows, scene, "primary", &contender, name) > 0.0);
            }
            assert!(
                figure(
                    rows,
                    scene,
                    "primary",
                    &contender,
                    "refitted_mrays_prebuilt"
                ) > 0.0
            );
        }
    }
    assert!(report.contains("## Refit: new boxes for a moved mesh"));

    // Images: three samplers at 1, 2 and 4 spp; more samples, less error (the renders are
    // deterministic, so this is a fixed fact of this scene, not a chance).
    for sampler in ["independent", "stratified", "sobol"] {
        let rmse = |spp: u32| {
            let contender = format!("raykernel render {sampler} {spp}spp");
            let scene = json["images"][0]["scene"].as_str().unwrap().to_owned();
            figure(rows, &scene, "-", &contender, "rmse")
        };
        assert!(rmse(4) < rmse(1) && rmse(1) > 0.0, "{sampler}");
    }

    // Plots: PNG files.
    for plot in [
        "speed_primary",
        "speed_incoherent",
        "error_vs_speed_primary",
        "error_vs_speed_incoherent",
        "scale_build",
        "scale_trace",
        "images_error_vs_time",
    ] {
        let bytes = std::fs::read(out.join("plots").join(format!("{plot}.png"))).unwrap();
        assert!(
            bytes.starts_with(b"\x89PNG\r\n\x1a\n"),
            "{plot} is not a PNG"
        );
    }
}

#[test]
fn bench_without_the_shared_scenes_says_what_is_missing() {
    let dir = temp_dir("bench_missing");
    let output = run_bench(&dir.join("no-such-dir"), &dir.join("out"), &[]);
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("scene directory") && stderr.contains("not found"),
        "{stderr}"
    );
    // Ray files asked for but absent: named, with the command that makes them.
    let scenes = scenes("bench_missing_rays");
    let output = Command::new(env!("CARGO_BIN_EXE_raykernel-bench"))
        .arg("--scenes")
        .arg(&scenes)
        .args(["--scene", "ball", "--no-city", "--rays"])
        .arg(scenes.join("no-rays"))
        .arg("--out")
        .arg(scenes.join("out"))
        .output()
        .unwrap();
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("make_rays.py"), "{stderr}");
}
