//! `host bench` end to end on a tiny generated scene (no `../shared` needed): the report, CSV,
//! JSON and plots are written and well-formed. No timing is checked, only structure and the
//! figures that do not depend on time (hit counts, agreement, accuracy).

mod common;

use common::{icosphere, temp_dir};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Two scenes (icospheres of 320 and 1280 triangles) with cameras in a fresh directory.
fn scenes(name: &str) -> PathBuf {
    let dir = temp_dir(name);
    for (scene, levels) in [("ball", 2), ("fine", 3)] {
        std::fs::write(
            dir.join(format!("{scene}.obj")),
            icosphere([0.25, -0.5, 0.0], 1.0, levels).to_obj(),
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
    Command::new(env!("CARGO_BIN_EXE_raykernel"))
        .arg("bench")
        .arg("--scenes")
        .arg(scenes)
        .args(["--scene", "ball", "--scene", "fine"])
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
        .args(["--image-spp", "4"])
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .expect("run the host binary")
}

#[test]
fn bench_writes_a_well_formed_report_csv_json_and_plots() {
    let dir = scenes("bench_report");
    let out = dir.join("out");
    let output = run_bench(&dir, &out, &[]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "host bench failed: {stderr}");

    // The last stdout line is the JSON summary naming the files.
    let stdout = String::from_utf8_lossy(&output.stdout);
    let summary: serde_json::Value = serde_json::from_str(stdout.lines().last().unwrap()).unwrap();
    assert_eq!(
        summary["report"],
        out.join("BENCHMARKS.md").display().to_string()
    );

    // Report: machine line first, the command, every section, every contender.
    let report = std::fs::read_to_string(out.join("BENCHMARKS.md")).unwrap();
    let mut lines = report.lines();
    assert_eq!(lines.next(), Some("# Benchmarks"));
    assert_eq!(lines.next(), Some(""));
    let machine = lines.next().unwrap();
    assert!(
        machine.starts_with("machine: ") && machine.contains("cores; rustc"),
        "{machine}"
    );
    assert!(
        report.contains("- command: `host bench --scenes"),
        "{report}"
    );
    for section in [
        "## Headline",
        "### Interleaved rounds",
        "## Traversal",
        "## Peers",
        "## Accuracy against an f64 reference",
        "## Images",
        "## Scale",
        "## Method",
    ] {
        assert!(report.contains(section), "missing {section}");
    }
    for contender in [
        "raykernel bvh4 sah f32",
        "raykernel bvh4 sah fixed",
        "raykernel bvh sah f32",
        "raykernel bvh sah fixed",
        "raykernel bvh sah f32 MT",
        "raykernel bvh median f32",
        "raykernel bvh midpoint fixed",
        "obvhs 0.4 BVH2",
        "obvhs 0.4 CWBVH",
        "bvh 0.13",
    ] {
        assert!(report.contains(contender), "missing {contender}");
    }
    // Markdown tables: every row has as many cells as its header.
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

    // CSV: the header, nine fields per line, finite numbers.
    let csv = std::fs::read_to_string(out.join("data.csv")).unwrap();
    let mut rows = csv.lines();
    assert_eq!(
        rows.next(),
        Some("section,scene,rays,contender,builder,test,mode,metric,value")
    );
    let mut count = 0;
    let mut sections = std::collections::BTreeSet::new();
    for row in rows {
        let fields: Vec<&str> = row.split(',').collect();
        assert_eq!(fields.len(), 9, "{row}");
        let value: f64 = fields[8].parse().unwrap_or_else(|_| panic!("{row}"));
        assert!(value.is_finite(), "{row}");
        sections.insert(fields[0].to_string());
        count += 1;
    }
    assert!(count > 100, "only {count} figures");
    for s in [
        "traversal",
        "peer",
        "agreement",
        "accuracy",
        "scale",
        "images",
        "fit",
        "rounds",
    ] {
        assert!(sections.contains(s), "no {s} figures in the CSV");
    }

    // JSON: 2 scenes × 2 ray sets × (17 of ours: 4-wide BVH and BVH 3 builders × 2 modes each,
    // Möller–Trumbore, grid and kd-tree × 2 modes; + the peers: 3, and tinybvh with the
    // `tinybvh` feature).
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("data.json")).unwrap()).unwrap();
    let rows = json["rows"].as_array().unwrap();
    assert_eq!(
        rows.len(),
        2 * 2 * (17 + host::bench::peers::Peer::ALL.len())
    );
    for row in rows {
        // A closed sphere seen from outside: every contender finds the same hits as ours,
        // and no contender leaks or invents hits against the f64 reference.
        let acc = &row["accuracy"];
        assert_eq!(acc["leaks"], 0, "{row}");
        assert_eq!(acc["false_hits"], 0, "{row}");
        assert_eq!(acc["rays"], 1024, "{row}");
        assert!(row["closest_mrays"].as_f64().unwrap() > 0.0, "{row}");
        if row["ours"] == false {
            assert_eq!(row["vs_ours"]["hitmiss"], 0, "{row}");
        }
    }
    // Interleaved rounds: one row per scene and ray set, three rounds of ours, and three of
    // tinybvh when the peer is in this build.
    let rounds = json["rounds"].as_array().unwrap();
    assert_eq!(rounds.len(), 2 * 2);
    let with_tinybvh =
        host::bench::peers::Peer::ALL.contains(&host::bench::peers::Peer::TinybvhBvh2);
    for row in rounds {
        assert_eq!(row["ray_count"], 1024, "{row}");
        let ours = row["ours_mrays"].as_array().unwrap();
        assert_eq!(ours.len(), 3, "{row}");
        assert!(ours.iter().all(|v| v.as_f64().unwrap() > 0.0), "{row}");
        let peer = row["peer_mrays"].as_array().unwrap();
        assert_eq!(peer.len(), if with_tinybvh { 3 } else { 0 }, "{row}");
    }

    // Scale: two sizes × two modes, the exact instance triangle counts plus the ground.
    let scale = json["scale"].as_array().unwrap();
    assert_eq!(scale.len(), 4);
    assert!(scale[0]["triangles"].as_u64().unwrap() >= 500);

    // Images: three samplers at 1, 2 and 4 spp; more samples, less error (the renders are
    // deterministic, so this is a fixed fact of this scene, not a chance).
    let images = json["images"].as_array().unwrap();
    assert_eq!(images.len(), 3 * 3);
    for sampler in ["independent", "stratified", "sobol"] {
        let rmse = |spp: u64| {
            images
                .iter()
                .find(|r| r["sampler"] == sampler && r["spp"] == spp)
                .and_then(|r| r["rmse"].as_f64())
                .unwrap()
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
    let output = Command::new(env!("CARGO_BIN_EXE_raykernel"))
        .arg("bench")
        .arg("--scenes")
        .arg(&scenes)
        .args(["--scene", "ball", "--rays"])
        .arg(scenes.join("no-rays"))
        .arg("--out")
        .arg(scenes.join("out"))
        .output()
        .unwrap();
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("make_rays.py"), "{stderr}");
}
