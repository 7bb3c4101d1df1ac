//! The `host` binary: bad files and arguments give one message on stderr and a non-zero exit,
//! never a panic; a good run prints its JSON report as the last stdout line.

mod common;

use common::{icosphere, random_rays, temp_dir, Rng};
use host::rayfile::{write_hits, write_rays};
use host::HitRecord;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn host(args: &[&Path]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raykernel"))
        .args(args)
        .output()
        .expect("run the host binary")
}

fn p(s: &str) -> PathBuf {
    PathBuf::from(s)
}

/// Valid scene and ray files in a fresh directory.
fn fixture(name: &str) -> (PathBuf, PathBuf, PathBuf) {
    let dir = temp_dir(name);
    let obj = dir.join("s.obj");
    std::fs::write(&obj, icosphere([0.0; 3], 1.0, 1).to_obj()).unwrap();
    let rays = dir.join("s.rays");
    write_rays(
        &rays,
        &random_rays(&mut Rng::new(3), [-2.0; 3], [2.0; 3], 50),
    )
    .unwrap();
    (dir, obj, rays)
}

/// Asserts a clean failure: exit code, no stdout, one stderr line containing `needle`.
fn assert_fails(out: &Output, code: i32, needle: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "stderr: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(stderr.contains(needle), "expected {needle:?} in: {stderr}");
    assert!(
        out.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
}

#[test]
fn trace_prints_a_json_report_as_the_last_line() {
    let (dir, obj, rays) = fixture("cli_ok");
    let hits = dir.join("s.hits");
    let out = host(&[
        &p("trace"),
        &obj,
        &rays,
        &p("--out"),
        &hits,
        &p("--mode"),
        &p("fixed"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8(out.stdout).unwrap();
    let last = stdout.lines().last().unwrap();
    let v: serde_json::Value = serde_json::from_str(last).unwrap();
    for key in [
        "scene",
        "rays_file",
        "accel",
        "builder",
        "mode",
        "leaf",
        "leaf_order",
        "runs",
        "stride",
        "triangles",
        "build_ms",
        "trace_ms",
        "rays",
        "mrays_per_s",
        "per_ray_ms",
        "mrays_per_s_prebuilt",
        "setup_ns_per_ray",
        "hits",
        "bad_rays",
        "nodes",
        "bytes_per_tri",
        "depth",
    ] {
        assert!(v.get(key).is_some(), "{key} missing from {last}");
    }
    assert_eq!(v["accel"], "bvh4");
    assert_eq!(v["builder"], "sah");
    assert_eq!(v["mode"], "fixed");
    assert_eq!(v["triangles"], 80);
    assert_eq!(v["rays"], 50);
    assert_eq!(v["runs"], 1);
    assert_eq!(v["leaf_order"], false);
    assert_eq!(std::fs::metadata(&hits).unwrap().len(), 50 * 8);

    let same = host(&[&p("compare-hits"), &hits, &hits]);
    assert!(same.status.success());
    let v: serde_json::Value =
        serde_json::from_str(String::from_utf8(same.stdout).unwrap().trim()).unwrap();
    assert_eq!(v["n"], 50);
    assert_eq!(v["same_prim_pct"], 100.0);
    assert_eq!(v["hitmiss"], 0);
}

#[test]
fn missing_scene_or_rays_fail_cleanly() {
    let (dir, obj, rays) = fixture("cli_missing");
    let hits = dir.join("x.hits");
    let none = dir.join("none.obj");
    let out = host(&[&p("trace"), &none, &rays, &p("--out"), &hits]);
    assert_fails(&out, 1, "none.obj: cannot read");
    let none = dir.join("none.rays");
    let out = host(&[&p("trace"), &obj, &none, &p("--out"), &hits]);
    assert_fails(&out, 1, "none.rays: cannot read");
    let out = host(&[
        &p("trace"),
        &obj,
        &rays,
        &p("--out"),
        &dir.join("no/dir.hits"),
    ]);
    assert_fails(&out, 1, "dir.hits: cannot write");
}

#[test]
fn bad_obj_names_its_line() {
    let (dir, _, rays) = fixture("cli_bad_obj");
    let obj = dir.join("bad.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n").unwrap();
    let out = host(&[&p("trace"), &obj, &rays, &p("--out"), &dir.join("x.hits")]);
    assert_fails(&out, 1, "bad.obj:4: vertex index 7 out of range");
    std::fs::write(&obj, b"\xff\xfe garbage\x00\n").unwrap();
    let out = host(&[&p("trace"), &obj, &rays, &p("--out"), &dir.join("x.hits")]);
    assert_fails(&out, 1, "bad.obj:1: no faces");
    // Representable in f32, not in fixed point.
    std::fs::write(&obj, "v 0 0 0\nv 10000 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let out = host(&[
        &p("trace"),
        &obj,
        &rays,
        &p("--out"),
        &dir.join("x.hits"),
        &p("--mode"),
        &p("fixed"),
    ]);
    assert_fails(&out, 1, "bad.obj:2: vertex unusable in fixed mode");
}

#[test]
fn ray_file_of_wrong_length_is_rejected() {
    let (dir, obj, _) = fixture("cli_bad_rays");
    let rays = dir.join("short.rays");
    std::fs::write(&rays, [0u8; 100]).unwrap();
    let out = host(&[&p("trace"), &obj, &rays, &p("--out"), &dir.join("x.hits")]);
    assert_fails(
        &out,
        1,
        "short.rays: not a ray file: length 100 bytes is not a multiple of 32",
    );
}

#[test]
fn bad_arguments_are_usage_errors() {
    let (dir, obj, rays) = fixture("cli_bad_args");
    let hits = dir.join("x.hits");
    let base = [
        &p("trace"),
        obj.as_path(),
        rays.as_path(),
        &p("--out"),
        hits.as_path(),
    ];
    for (extra, needle) in [
        (
            vec!["--mode", "double"],
            "invalid value 'double' for '--mode",
        ),
        (vec!["--accel", "octree"], "invalid value 'octree'"),
        (vec!["--builder", "lbvh"], "invalid value 'lbvh'"),
        (vec!["--leaf", "0"], "--leaf"),
        (vec!["--leaf", "65"], "--leaf"),
        (vec!["--stride", "0"], "--stride"),
        (vec!["--stride=-3"], "--stride"),
        (vec!["--bogus"], "unexpected argument '--bogus'"),
        (vec!["--runs", "0"], "--runs"),
        (
            vec!["--leaf-order", "--accel", "linear"],
            "--leaf-order needs --accel bvh",
        ),
    ] {
        let extra: Vec<PathBuf> = extra.into_iter().map(p).collect();
        let args: Vec<&Path> = base
            .iter()
            .copied()
            .chain(extra.iter().map(|e| e.as_path()))
            .collect();
        assert_fails(&host(&args), 2, needle);
    }
    // --out is required.
    assert_fails(&host(&[&p("trace"), &obj, &rays]), 2, "--out");
    assert_fails(&host(&[&p("draw")]), 2, "unrecognized subcommand");
    // The renderer has no 4-wide BVH.
    assert_fails(
        &host(&[&p("render"), &p("--accel"), &p("bvh4"), &p("--out"), &hits]),
        2,
        "--accel bvh4 is for `raykernel trace` only",
    );
}

#[test]
fn compare_hits_rejects_files_of_different_lengths() {
    let dir = temp_dir("cli_compare");
    let (a, b) = (dir.join("a.hits"), dir.join("b.hits"));
    write_hits(&a, &[HitRecord::MISS; 3]).unwrap();
    write_hits(&b, &[HitRecord::MISS; 4]).unwrap();
    assert_fails(
        &host(&[&p("compare-hits"), &a, &b]),
        1,
        "a.hits has 3 records",
    );
    std::fs::write(&b, [0u8; 7]).unwrap();
    assert_fails(
        &host(&[&p("compare-hits"), &a, &b]),
        1,
        "not a multiple of 8",
    );
}

/// Runs `host` and parses its last stdout line as JSON; panics (with stderr) on failure.
fn host_json(args: &[&Path]) -> serde_json::Value {
    let out = host(args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8(out.stdout).unwrap();
    serde_json::from_str(stdout.lines().last().unwrap()).unwrap()
}

#[test]
fn compare_hits_classifies_fixed_vs_f32_differences() {
    let dir = temp_dir("cli_classify");
    let obj = dir.join("s.obj");
    std::fs::write(&obj, icosphere([0.1, 0.2, -0.3], 1.5, 3).to_obj()).unwrap();
    let rays = dir.join("s.rays");
    let mut rng = Rng::new(11);
    write_rays(&rays, &random_rays(&mut rng, [-2.5; 3], [2.5; 3], 3000)).unwrap();
    let (f, x) = (dir.join("f32.hits"), dir.join("fixed.hits"));
    for (mode, hits) in [("f32", &f), ("fixed", &x)] {
        host_json(&[
            &p("trace"),
            &obj,
            &rays,
            &p("--out"),
            hits,
            &p("--mode"),
            &p(mode),
        ]);
    }
    let v = host_json(&[
        &p("compare-hits"),
        &f,
        &x,
        &p("--scene"),
        &obj,
        &p("--rays"),
        &rays,
    ]);
    assert_eq!(v["n"], 3000);
    assert_eq!(v["bound"], "4*sqrt(3)*2^-17 + t*2^-28");
    let count = |k: &str| v[k].as_u64().unwrap_or_else(|| panic!("{k} in {v}"));
    assert_eq!(
        count("differing"),
        count("explained_by_quantization")
            + count("explained_by_depth")
            + count("explained_by_origin")
            + count("unexplained"),
        "{v}"
    );
    assert_eq!(count("unexplained"), 0, "{v}");
    assert!(
        v["max_edge_distance_of_differing"].as_f64().unwrap() <= 1e-4,
        "{v}"
    );

    // Without --scene/--rays: no classification fields.
    let plain = host_json(&[&p("compare-hits"), &f, &x]);
    assert!(plain.get("differing").is_none(), "{plain}");

    // --scene and --rays go together.
    assert_fails(
        &host(&[&p("compare-hits"), &f, &x, &p("--scene"), &obj]),
        2,
        "--rays",
    );
    assert_fails(
        &host(&[&p("compare-hits"), &f, &x, &p("--rays"), &rays]),
        2,
        "--scene",
    );
    // A ray file that does not go with the hits.
    let short = dir.join("short.rays");
    write_rays(&short, &random_rays(&mut rng, [-2.5; 3], [2.5; 3], 10)).unwrap();
    let args = [
        &p("compare-hits"),
        &f,
        &x,
        &p("--scene"),
        &obj,
        &p("--rays"),
    ];
    let mut with_short: Vec<&Path> = args.iter().map(|a| a.as_path()).collect();
    with_short.push(&short);
    assert_fails(
        &host(&with_short),
        1,
        "the hit files have 3000 records but the ray file has 10 rays",
    );
    // Hits naming a triangle the scene does not have.
    let bogus = dir.join("bogus.hits");
    write_hits(
        &bogus,
        &vec![
            HitRecord {
                t: 1.0,
                prim: 99_999
            };
            3000
        ],
    )
    .unwrap();
    assert_fails(
        &host(&[
            &p("compare-hits"),
            &f,
            &bogus,
            &p("--scene"),
            &obj,
            &p("--rays"),
            &rays,
        ]),
        1,
        "hits triangle 99999, but the scene has 1280 triangles",
    );
}

fn render_args(args: &[&str]) -> host::cli::RenderArgs {
    use clap::Parser;
    let mut all = vec!["raykernel", "render"];
    all.extend(args);
    match host::cli::Cli::try_parse_from(all).unwrap().command {
        host::cli::Command::Render(a) => a,
        other => panic!("{other:?}"),
    }
}

#[test]
fn width_or_height_alone_keeps_every_built_in_scene_aspect_ratio() {
    for scene in raykernel::render::scenes::ALL {
        let (w0, h0) = (scene.settings.width, scene.settings.height);
        for side in [97u32, 256, 1024] {
            let round = |a: u32, num: u32, den: u32| {
                ((u64::from(a) * u64::from(num) + u64::from(den) / 2) / u64::from(den)) as u32
            };
            let s = side.to_string();
            let by_width = render_args(&[scene.name, "--explain", "--width", &s]);
            let r = host::cli::run_render(&by_width).unwrap();
            assert_eq!(
                (r.width, r.height),
                (side, round(side, h0, w0)),
                "{}",
                scene.name
            );
            let by_height = render_args(&[scene.name, "--explain", "--height", &s]);
            let r = host::cli::run_render(&by_height).unwrap();
            assert_eq!(
                (r.width, r.height),
                (round(side, w0, h0), side),
                "{}",
                scene.name
            );
        }
    }
}

#[test]
fn out_into_a_missing_directory_fails_before_rendering() {
    let dir = temp_dir("cli_out_missing");
    let png = dir.join("no/such/dir/pic.png");
    let start = std::time::Instant::now();
    // Minutes of work if it started rendering.
    let out = Command::new(env!("CARGO_BIN_EXE_raykernel"))
        .args(["render", "--width", "4096", "--spp", "4096", "--out"])
        .arg(&png)
        .output()
        .unwrap();
    let took = start.elapsed();
    assert_fails(&out, 1, "cannot write: the directory");
    assert!(String::from_utf8_lossy(&out.stderr).contains("does not exist"));
    assert!(took < std::time::Duration::from_secs(1), "took {took:?}");
}

#[test]
fn out_must_name_a_png_and_linear_a_pfm() {
    let dir = temp_dir("cli_out_ext");
    let jpg = dir.join("pic.jpg");
    let out = host(&[&p("render"), &p("--out"), &jpg]);
    assert_fails(&out, 2, "pic.jpg: `.jpg`, but it writes a PNG image");
    assert!(!jpg.exists());
    let png = dir.join("pic.png");
    let exr = dir.join("pic.exr");
    let out = host(&[&p("render"), &p("--out"), &png, &p("--linear"), &exr]);
    assert_fails(&out, 2, "--linear");
    assert!(!png.exists(), "the reserved PNG is removed again");
}

#[test]
fn the_plan_line_prints_before_the_render() {
    use std::io::{BufRead, BufReader};
    let dir = temp_dir("cli_plan_first");
    let png = dir.join("slow.png");
    let mut child = Command::new(env!("CARGO_BIN_EXE_raykernel"))
        .args([
            "render",
            "--width",
            "1024",
            "--spp",
            "1024",
            "--threads",
            "1",
            "--out",
        ])
        .arg(&png)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    let still_running = child.try_wait().unwrap().is_none();
    child.kill().unwrap();
    let _ = child.wait();
    assert!(first.starts_with("plan: anti-aliasing on"), "{first}");
    assert!(still_running, "the plan came only after the render");
}

#[test]
fn quiet_prints_only_the_json_report() {
    for flags in [vec!["--quiet", "render"], vec!["render", "-q"]] {
        let mut args = flags.clone();
        args.extend(["spheres", "--explain"]);
        let out = Command::new(env!("CARGO_BIN_EXE_raykernel"))
            .args(&args)
            .output()
            .unwrap();
        assert!(out.status.success());
        let stdout = String::from_utf8(out.stdout).unwrap();
        assert_eq!(stdout.lines().count(), 1, "{stdout}");
        let v: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
        assert_eq!(v["scene"], "spheres");
    }
}

#[test]
fn completions_are_generated_for_the_raykernel_binary() {
    let out = host(&[&p("completions"), &p("bash")]);
    assert!(out.status.success());
    let script = String::from_utf8(out.stdout).unwrap();
    assert!(script.contains("_raykernel()"), "{script}");
    assert!(
        script.contains("--look-at"),
        "render's camera flags are completed"
    );
    assert_fails(&host(&[&p("completions"), &p("tcsh")]), 2, "invalid value");
}

#[test]
fn fixed_mode_trace_reports_the_rays_it_rejected() {
    let (dir, obj, _) = fixture("cli_rejected");
    let mut rays = random_rays(&mut Rng::new(5), [-2.0; 3], [2.0; 3], 20);
    rays[3].origin = [9000.0, 0.0, 0.0];
    rays[11].origin = [0.0, -1e6, 0.0];
    let path = dir.join("far.rays");
    write_rays(&path, &rays).unwrap();
    let hits = dir.join("far.hits");
    let out = host(&[
        &p("trace"),
        &obj,
        &path,
        &p("--out"),
        &hits,
        &p("--mode"),
        &p("fixed"),
    ]);
    assert!(out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.starts_with(
            "warning: 2 of 20 traced rays rejected in fixed mode and written as misses; the \
             first is record 3 of "
        ),
        "{stderr}"
    );
    assert!(
        stderr.contains(
            "ray origin: coordinate outside [-8192, 8192], the coordinate range of fixed mode"
        ),
        "{stderr}"
    );
    let stdout = String::from_utf8(out.stdout).unwrap();
    let v: serde_json::Value = serde_json::from_str(stdout.lines().last().unwrap()).unwrap();
    assert_eq!(
        (v["bad_rays"].as_u64(), v["first_bad_ray"].as_u64()),
        (Some(2), Some(3))
    );
    // Nothing to report in f32 mode.
    let out = host(&[&p("trace"), &obj, &path, &p("--out"), &hits]);
    assert!(out.status.success() && out.stderr.is_empty());
}

#[test]
fn binary_bytes_in_an_obj_are_escaped_in_the_message() {
    let (dir, _, rays) = fixture("cli_binary_obj");
    let obj = dir.join("binary.obj");
    std::fs::write(&obj, b"v 1 2 \x1b[2J\x07\nf 1 2 3\n").unwrap();
    let out = host(&[&p("trace"), &obj, &rays, &p("--out"), &dir.join("x.hits")]);
    assert_fails(&out, 1, "binary.obj:1: malformed number `\\u{1b}[2J\\u{7}`");
    assert!(!out.stderr.contains(&0x1b) && !out.stderr.contains(&0x07));
}

#[test]
fn check_says_up_front_how_many_renders_it_compares() {
    let out = Command::new(env!("CARGO_BIN_EXE_raykernel"))
        .args([
            "check", "spheres", "--mode", "fixed", "--spp", "1", "--width", "8",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = stdout.lines().collect();
    let per_case = host::check::renders_per_case();
    assert_eq!(
        lines[0],
        format!(
            "check: 1 scene(s) × 1 mode(s), {per_case} renders each (the kernel's reference \
             and {} ways to match it): {per_case} renders, 0.0 M samples per mode",
            per_case - 1
        )
    );
    let v: serde_json::Value = serde_json::from_str(lines.last().unwrap()).unwrap();
    assert_eq!(v["renders"].as_u64(), Some(per_case as u64 - 1));
}
