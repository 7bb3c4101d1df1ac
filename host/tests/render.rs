//! `host render`: built-in scenes in both modes through the command line, thread-count and
//! tile-size independence, PNG and PFM output, the plan, OBJ scenes (framed or with a `.camera`
//! file), and clean failures for bad arguments and files.

mod common;

use common::{icosphere, temp_dir};
use host::cli::{run_render, CameraArgs, RenderArgs, SettingsArgs};
use host::render::{decode_png, render, RenderOptions};
use host::trace::{Builder, Mode};
use raykernel::bvh::BuildOptions;
use raykernel::render::scenes;
use raykernel::AccelKind;
use std::path::{Path, PathBuf};
use std::process::Command;

fn host(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_raykernel"))
        .args(args)
        .output()
        .unwrap()
}

fn assert_fails(out: &std::process::Output, code: i32, needle: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(stderr.contains(needle), "expected {needle:?} in {stderr}");
    assert!(out.stdout.is_empty());
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn small(scene: Option<PathBuf>, out: PathBuf, mode: Mode) -> RenderArgs {
    RenderArgs {
        scene: scene.map(|p| p.display().to_string()),
        out: Some(out),
        linear: None,
        exr: None,
        dump_scene: None,
        explain: false,
        settings: SettingsArgs {
            width: Some(40),
            height: Some(30),
            spp: Some(2),
            ..SettingsArgs::default()
        },
        camera: CameraArgs::default(),
        mode,
        threads: Some(2),
        accel: AccelKind::Bvh(BuildOptions::DEFAULT),
        builder: Builder::Sah,
        no_reinsertion: false,
        leaf: 4,
        tile: 16,
    }
}

#[test]
fn default_scene_renders_in_both_modes_from_the_command_line() {
    let dir = temp_dir("render_cli");
    for mode in ["f32", "fixed"] {
        let png = dir.join(format!("cornell_{mode}.png"));
        let pfm = dir.join(format!("cornell_{mode}.pfm"));
        let out = host(&[
            "render",
            "--out",
            s(&png),
            "--linear",
            s(&pfm),
            "--width",
            "32",
            "--height",
            "24",
            "--spp",
            "2",
            "--mode",
            mode,
            "--threads",
            "2",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let stdout = String::from_utf8(out.stdout).unwrap();
        let lines: Vec<_> = stdout.lines().collect();
        assert_eq!(lines.len(), 3, "{stdout}");
        assert!(
            lines[0].starts_with("plan: anti-aliasing on"),
            "{}",
            lines[0]
        );
        assert!(lines[1].starts_with("rendered cornell") && lines[1].contains("Mrays/s"));
        let v: serde_json::Value = serde_json::from_str(lines[2]).unwrap();
        assert_eq!(
            (v["width"].as_u64(), v["height"].as_u64()),
            (Some(32), Some(24))
        );
        assert_eq!(v["mode"], mode);
        assert_eq!(v["camera_rays"], 32 * 24 * 2);
        assert!(v["shadow_rays"].as_u64().unwrap() > 0);
        assert!(v["reflection_rays"].as_u64().unwrap() > 0);
        // Built-in scenes render with the path integrator (indirect light) by default.
        for effect in [
            "depth of field on",
            "motion blur on",
            "soft shadows on",
            "path tracing (max length 5 segments",
        ] {
            assert!(v["plan"].as_str().unwrap().contains(effect), "{effect}");
        }
        let image = decode_png(&std::fs::read(&png).unwrap()).unwrap();
        assert_eq!((image.width, image.height), (32, 24));
        let pfm = std::fs::read(&pfm).unwrap();
        assert!(pfm.starts_with(b"PF\n32 24\n-1.0\n"));
        assert_eq!(pfm.len(), b"PF\n32 24\n-1.0\n".len() + 32 * 24 * 12);
    }
}

#[test]
fn explain_prints_the_plan_without_rendering() {
    let out = host(&["render", "spheres", "--explain"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<_> = stdout.lines().collect();
    assert_eq!(lines.len(), 2, "{stdout}");
    assert_eq!(
        lines[0],
        "plan: anti-aliasing on (64 spp, sobol, tent filter); depth of field off; motion blur \
         off; lights: 2 point, 0 area (soft shadows off); path tracing (max length 5 segments, \
         Russian roulette after 3, light and BSDF sampling with MIS)"
    );
    let v: serde_json::Value = serde_json::from_str(lines[1]).unwrap();
    assert_eq!(
        (v["width"].as_u64(), v["height"].as_u64()),
        (Some(512), Some(384))
    );
    assert!(v.get("rays").is_none() && v["out"].is_null());
}

#[test]
fn tiles_and_threads_do_not_change_a_pixel() {
    let d = scenes::MOTION;
    let mut settings = d.settings;
    settings.width = 37;
    settings.height = 29;
    for mode in [Mode::F32, Mode::Fixed] {
        let render_with = |threads, tile| {
            let o = RenderOptions {
                mode,
                threads,
                tile,
                ..RenderOptions::default()
            };
            render(&d, settings, &o).unwrap()
        };
        let one = render_with(1, (37, 29));
        for (threads, tile) in [(2, (16, 16)), (3, (5, 3)), (4, (1, 1))] {
            let other = render_with(threads, tile);
            assert!(one.frame == other.frame, "{mode:?} {threads} {tile:?}");
            assert_eq!(one.stats, other.stats);
        }
    }
}

#[test]
fn obj_scene_is_framed_or_uses_its_camera_file() {
    let dir = temp_dir("render_obj");
    let obj = dir.join("ball.obj");
    std::fs::write(&obj, icosphere([10.0, -3.0, 2.0], 1.5, 2).to_obj()).unwrap();
    let mut lit: Vec<u8> = Vec::new();
    for mode in [Mode::F32, Mode::Fixed] {
        let out = dir.join(format!("framed.{mode:?}.png"));
        let report = run_render(&small(Some(obj.clone()), out.clone(), mode)).unwrap();
        assert_eq!(report.triangles, 320);
        assert!(report.plan.contains("1 point, 1 area"), "{}", report.plan);
        let image = decode_png(&std::fs::read(&out).unwrap()).unwrap();
        // Framed: the ball is in the middle, lit from above, brighter than the background.
        let at = |x: usize, y: usize| image.rgb[3 * (y * 40 + x)];
        assert!(at(20, 15) > at(0, 0) + 10, "{} {}", at(20, 15), at(0, 0));
        assert!(
            at(20, 10) > at(20, 20) + 40,
            "{} {}",
            at(20, 10),
            at(20, 20)
        );
        lit.push(at(20, 15));
    }
    assert!(lit[0].abs_diff(lit[1]) <= 2, "{lit:?}");
    // A camera file beside it wins; looking away from the ball, all is background.
    std::fs::write(
        dir.join("ball.camera"),
        "eye 10 -3 20\ntarget 10 -3 40 # away\nup 0 1 0\nvfov 30\n",
    )
    .unwrap();
    let out = dir.join("away.png");
    let report = run_render(&small(Some(obj), out.clone(), Mode::F32)).unwrap();
    let f = report.figures.unwrap();
    assert_eq!((f.shadow_rays, f.reflection_rays), (0, 0));
    let image = decode_png(&std::fs::read(&out).unwrap()).unwrap();
    assert!(image.rgb.chunks(3).all(|p| p == &image.rgb[..3]));
}

#[test]
fn bad_arguments_and_files_fail_with_one_message() {
    let dir = temp_dir("render_fail");
    let png = dir.join("out.png");
    let missing = dir.join("missing.obj");
    assert_fails(
        &host(&["render", s(&missing), "--out", s(&png)]),
        1,
        "missing.obj: cannot read",
    );
    let bad = dir.join("bad.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nf 1 2 3\n").unwrap();
    assert_fails(
        &host(&["render", s(&bad), "--out", s(&png)]),
        1,
        "bad.obj:3: vertex index 3 out of range",
    );
    let ball = dir.join("ball.obj");
    std::fs::write(&ball, icosphere([0.0; 3], 1.0, 1).to_obj()).unwrap();
    std::fs::write(dir.join("ball.camera"), "eye 0 0 5\ntarget 0 0 0\nup 0 1\n").unwrap();
    assert_fails(
        &host(&["render", s(&ball), "--out", s(&png)]),
        1,
        "ball.camera:3: `up` needs 3 numbers, got 2",
    );
    std::fs::remove_file(dir.join("ball.camera")).unwrap();
    let small = ["--width", "8", "--height", "8", "--spp", "1"];
    let mut a = vec!["render", s(&ball), "--out", "no/such/dir.png"];
    a.extend(small);
    assert_fails(&host(&a), 1, "dir.png: cannot write");
    // Far beyond the fixed-point range: the OBJ's line.
    let far = dir.join("far.obj");
    std::fs::write(&far, "v 0 0 0\nv 20000 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let mut a = vec!["render", s(&far), "--out", s(&png), "--mode", "fixed"];
    a.extend(small);
    assert_fails(&host(&a), 1, "far.obj:2: vertex unusable in fixed mode");
    assert_fails(
        &host(&["render", "kitchen-sink", "--out", s(&png)]),
        2,
        "unknown scene `kitchen-sink`: expected a built-in scene (cornell, spheres, motion)",
    );
    for (extra, needle) in [
        (vec![], "--out"),
        (vec!["--out", "x.png", "--width", "0"], "--width"),
        (vec!["--out", "x.png", "--spp", "0"], "--spp"),
        (vec!["--out", "x.png", "--threads", "0"], "--threads"),
        (
            vec!["--out", "x.png", "--mode", "f64"],
            "invalid value 'f64'",
        ),
        (
            vec!["--out", "x.png", "--accel", "octree"],
            "invalid value 'octree'",
        ),
        (
            vec!["--out", "x.png", "--sampler", "halton"],
            "invalid value 'halton'",
        ),
        (
            vec!["--out", "x.png", "a.obj", "b.obj"],
            "unexpected argument",
        ),
    ] {
        let mut a = vec!["render"];
        a.extend(extra);
        assert_fails(&host(&a), 2, needle);
    }
}

#[test]
fn the_path_integrator_is_chosen_on_the_command_line() {
    let out = host(&[
        "render",
        "cornell",
        "--integrator",
        "path",
        "--max-path-length",
        "6",
        "--explain",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert!(
        stdout.contains("path tracing (max length 6 segments, Russian roulette after 3"),
        "{stdout}"
    );
    let out = host(&["render", "cornell", "--max-path-length", "0", "--explain"]);
    assert!(!out.status.success());
}
