//! `host render`: the built-in scene in both modes, thread-count independence, PNG output, an
//! OBJ with and without a `.camera` file, and clean failures.

mod common;

use common::{icosphere, temp_dir};
use host::cli::{run_render, RenderArgs};
use host::render::{encode_png, render, Image, RenderConfig};
use host::scene::Scene;
use host::trace::{Builder, Mode};
use raykernel::bvh::BuildOptions;
use std::path::{Path, PathBuf};
use std::process::Command;

fn config(mode: Mode, threads: usize) -> RenderConfig {
    RenderConfig {
        width: 64,
        height: 48,
        mode,
        threads,
        build: BuildOptions::default(),
    }
}

fn decode(bytes: &[u8]) -> (png::OutputInfo, Vec<u8>) {
    let mut reader = png::Decoder::new(std::io::Cursor::new(bytes))
        .read_info()
        .unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    (info, buf)
}

#[test]
fn built_in_scene_is_the_same_for_any_thread_count_in_both_modes() {
    let scene = Scene::built_in();
    let mut images = Vec::new();
    for mode in [Mode::F32, Mode::Fixed] {
        let (one, stats) = render(&scene, &config(mode, 1)).unwrap();
        assert_eq!(one.rgb.len(), 64 * 48 * 3);
        assert_eq!(stats.primary_rays, 64 * 48);
        assert_eq!(stats.threads, 1);
        // The box fills the middle of the view; sky all around it.
        assert!(
            stats.hits > 64 * 48 / 4 && stats.hits < 64 * 48 * 3 / 4,
            "{stats:?}"
        );
        assert!(stats.shadow_rays > 0 && stats.shadow_rays <= stats.hits);
        let (three, stats3) = render(&scene, &config(mode, 3)).unwrap();
        assert_eq!(stats3.threads, 3);
        assert!(one == three, "{mode:?}: 1 and 3 threads differ");
        assert_eq!(stats3.rays(), stats.rays());
        // More threads than rows.
        let mut tall = config(mode, 7);
        tall.height = 4;
        let (few, s) = render(&scene, &tall).unwrap();
        assert_eq!((few.rgb.len(), s.threads), (64 * 4 * 3, 4));
        images.push(one);
    }
    // The modes differ at most on a few edge pixels.
    let differ = images[0]
        .rgb
        .chunks(3)
        .zip(images[1].rgb.chunks(3))
        .filter(|(a, b)| a != b)
        .count();
    assert!(
        differ < 64 * 48 / 50,
        "{differ} pixels differ between f32 and fixed"
    );
}

#[test]
fn png_decodes_to_the_rendered_pixels() {
    let (image, _) = render(&Scene::built_in(), &config(Mode::F32, 2)).unwrap();
    let (info, pixels) = decode(&encode_png(&image).unwrap());
    assert_eq!((info.width, info.height), (64, 48));
    assert_eq!(info.color_type, png::ColorType::Rgb);
    assert_eq!(info.bit_depth, png::BitDepth::Eight);
    assert!(pixels == image.rgb);
    // Top-left is sky: pale blue, blue the largest channel.
    let [r, g, b] = [pixels[0], pixels[1], pixels[2]];
    assert!(b > r && b >= g && r > 150, "{r} {g} {b}");
    let tiny = Image {
        width: 1,
        height: 1,
        rgb: vec![1, 2, 3],
    };
    assert_eq!(decode(&encode_png(&tiny).unwrap()).1, [1, 2, 3]);
}

fn args(scene: Option<PathBuf>, out: PathBuf, mode: Mode) -> RenderArgs {
    RenderArgs {
        scene,
        out,
        width: 40,
        height: 30,
        mode,
        threads: Some(2),
        builder: Builder::Sah,
        leaf: 4,
    }
}

#[test]
fn obj_scene_is_framed_or_uses_its_camera_file() {
    let dir = temp_dir("render_obj");
    let obj = dir.join("ball.obj");
    std::fs::write(&obj, icosphere([10.0, -3.0, 2.0], 1.5, 2).to_obj()).unwrap();
    for mode in [Mode::F32, Mode::Fixed] {
        let out = dir.join(format!("framed.{mode:?}.png"));
        let report = run_render(&args(Some(obj.clone()), out.clone(), mode)).unwrap();
        assert_eq!(report.camera, "framed");
        assert_eq!(report.triangles, 320);
        // Framed: the ball is in the middle and the border is sky.
        assert!(
            report.hits > 100 && report.hits < 40 * 30 - 100,
            "{report:?}"
        );
        let (info, pixels) = decode(&std::fs::read(&out).unwrap());
        assert_eq!((info.width, info.height), (40, 30));
        assert_eq!(pixels.len(), 40 * 30 * 3);
    }
    // A camera file beside it wins; looking away from the ball, everything is sky.
    std::fs::write(
        dir.join("ball.camera"),
        "eye 10 -3 20\ntarget 10 -3 40 # away\nup 0 1 0\nvfov 30\n",
    )
    .unwrap();
    let report = run_render(&args(Some(obj), dir.join("away.png"), Mode::F32)).unwrap();
    assert!(report.camera.ends_with("ball.camera"), "{}", report.camera);
    assert_eq!((report.hits, report.shadow_rays), (0, 0));
}

fn host(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_host"))
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

#[test]
fn cli_renders_and_fails_cleanly() {
    let dir = temp_dir("render_cli");
    let png = dir.join("out.png");
    let out = host(&[
        "render",
        "--out",
        s(&png),
        "--width",
        "32",
        "--height",
        "24",
        "--mode",
        "fixed",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<_> = stdout.lines().collect();
    assert_eq!(lines.len(), 2, "{stdout}");
    assert!(lines[0].starts_with("rendered built-in") && lines[0].contains("Mrays/s"));
    let v: serde_json::Value = serde_json::from_str(lines[1]).unwrap();
    assert_eq!(
        (v["width"].as_u64(), v["height"].as_u64()),
        (Some(32), Some(24))
    );
    assert_eq!(v["mode"], "fixed");
    assert_eq!(v["primary_rays"], 32 * 24);
    let (info, _) = decode(&std::fs::read(&png).unwrap());
    assert_eq!((info.width, info.height), (32, 24));

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
    assert_fails(
        &host(&["render", s(&ball), "--out", s(&dir.join("no/such/dir.png"))]),
        1,
        "dir.png: cannot write",
    );
    // Far beyond the fixed-point range.
    let far = dir.join("far.obj");
    std::fs::write(&far, "v 0 0 0\nv 20000 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    assert_fails(
        &host(&["render", s(&far), "--out", s(&png), "--mode", "fixed"]),
        1,
        "far.obj:2: vertex unusable in fixed mode",
    );
    for (extra, needle) in [
        (vec![], "--out"),
        (vec!["--out", "x.png", "--width", "0"], "--width"),
        (vec!["--out", "x.png", "--threads", "0"], "--threads"),
        (
            vec!["--out", "x.png", "--mode", "f64"],
            "invalid value 'f64'",
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
