//! `host check`: every built-in scene in both modes renders byte-identically through the
//! kernel's single-threaded path, the host's tiles at several thread counts and tile sizes, and
//! every accelerator; and a difference, however small, is reported at the right pixel.

use host::check::{check_scene, describe_differences, first_difference, CaseReport};
use host::cli::{run_check, CheckArgs, SettingsArgs};
use host::render::render_reference;
use host::spec::SceneSpec;
use host::trace::Mode;
use raykernel::render::{scenes, AccelChoice};
use std::process::Command;

#[test]
fn every_built_in_scene_renders_identically_every_way_in_both_modes() {
    let report = run_check(&CheckArgs {
        scenes: Vec::new(),
        mode: None,
        settings: SettingsArgs::default(),
    })
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(report.cases.len(), scenes::ALL.len() * 2);
    for case in &report.cases {
        assert!(case.differences.is_empty(), "{case:?}");
        assert!(case.compared >= 11, "{case:?}");
    }
    assert_eq!(report.differences, 0);
}

#[test]
fn check_command_exits_zero_and_prints_a_json_summary() {
    let out = Command::new(env!("CARGO_BIN_EXE_raykernel"))
        .args(["check", "spheres", "--mode", "fixed", "--spp", "2"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert!(
        stdout.starts_with("check: 1 scene(s) × 1 mode(s)"),
        "{stdout}"
    );
    assert!(
        stdout.lines().any(|l| l.starts_with("check passed: ")),
        "{stdout}"
    );
    let v: serde_json::Value = serde_json::from_str(stdout.lines().last().unwrap()).unwrap();
    assert_eq!(v["differences"], 0);
    assert_eq!(v["cases"][0]["scene"], "spheres");
    assert_eq!(v["cases"][0]["mode"], "fixed");
}

#[test]
fn a_one_bit_difference_is_reported_at_its_pixel_with_both_values() {
    let d = scenes::CORNELL;
    let reference = render_reference(&d, d.settings, Mode::F32, AccelChoice::default()).unwrap();
    let mut other = reference.clone();
    // Pixel (5, 9): its blue byte's lowest bit.
    let i = 3 * (9 * d.settings.width as usize + 5) + 2;
    other.rgb[i] ^= 1;
    let diff = first_difference(&reference, &other).unwrap();
    assert_eq!((diff.x, diff.y, diff.count), (5, 9, 1));
    assert_eq!(diff.expected[..2], diff.actual[..2]);
    assert_eq!(diff.expected[2] ^ 1, diff.actual[2]);
    let case = CaseReport {
        scene: "cornell".into(),
        mode: "f32",
        width: d.settings.width,
        height: d.settings.height,
        compared: 1,
        differences: vec![("host tiles (2 threads)".into(), diff)],
    };
    let lines = describe_differences(&[case]);
    assert_eq!(lines.len(), 1);
    assert!(
        lines[0].contains("cornell (f32): host tiles (2 threads) differs")
            && lines[0].contains("first at pixel (5, 9)")
            && lines[0].contains("(1 pixel differs)"),
        "{}",
        lines[0]
    );
    assert_eq!(first_difference(&reference, &reference), None);
}

#[test]
fn check_scene_reports_no_difference_for_a_scene_file_scene() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/scenes/example.json");
    let mut spec: SceneSpec = host::scenefile::load_scene_file(&path).unwrap();
    (spec.settings.width, spec.settings.height, spec.settings.spp) = (24, 16, 2);
    let r = check_scene(&spec, Mode::F32).unwrap();
    assert!(r.differences.is_empty(), "{r:?}");
}
