//! Scene files: the documented example loads and renders, every built-in scene round-trips
//! (dump, load, render: identical bytes, both modes), and bad files give one message naming the
//! file, the field and what was expected.

mod common;

use common::temp_dir;
use host::render::{render, Image, RenderOptions};
use host::scene::resolve_scene;
use host::scenefile::{dump, load_scene_file, parse_scene_file};
use host::spec::SceneSpec;
use host::trace::Mode;
use raykernel::render::scenes::{self, SceneData};
use raykernel::render::Settings;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::Command;

fn example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/scenes/example.json")
}

fn srgb(d: &SceneData<'_>, settings: Settings, mode: Mode) -> Image {
    let o = RenderOptions {
        mode,
        threads: 2,
        ..RenderOptions::default()
    };
    render(d, settings, &o).unwrap().frame.srgb8()
}

#[test]
fn example_scene_loads_and_renders_every_effect_in_both_modes() {
    let spec = load_scene_file(&example()).unwrap();
    assert_eq!(spec.name, "example");
    assert_eq!(spec.objects.len(), 6);
    assert_eq!(
        spec.triangles.len(),
        2 + 4,
        "floor and the tetrahedron from tetra.obj"
    );
    assert_eq!(spec.lights.len(), 3);
    assert_eq!((spec.settings.width, spec.settings.spp), (320, 16));
    let mut settings = spec.settings;
    (settings.width, settings.height, settings.spp) = (40, 30, 4);
    for mode in [Mode::F32, Mode::Fixed] {
        let o = RenderOptions {
            mode,
            threads: 2,
            ..RenderOptions::default()
        };
        let r = render(&spec.data(), settings, &o).unwrap();
        let p = r.plan;
        assert!(p.lens && p.motion && p.glossy && p.reflections);
        assert_eq!((p.point_lights, p.area_lights), (1, 2));
        let image = r.frame.srgb8();
        assert!(image.rgb.iter().any(|&b| b > 100), "{mode:?}: all dark");
    }
}

#[test]
fn every_built_in_scene_round_trips_through_a_scene_file() {
    let dir = temp_dir("round_trip");
    for d in scenes::ALL {
        let path = dir.join(format!("{}.json", d.name));
        let text = dump(&d, &[]);
        std::fs::write(&path, &text).unwrap();
        let loaded = load_scene_file(&path).unwrap();
        // The same data, bit for bit (names aside, which are the file's).
        assert_eq!(loaded.data(), d, "{}", d.name);
        // Dumping again gives the same text.
        assert_eq!(dump(&loaded.data(), &loaded.material_names), text);
        for mode in [Mode::F32, Mode::Fixed] {
            let a = srgb(&d, d.settings, mode);
            let b = srgb(&loaded.data(), loaded.settings, mode);
            assert!(
                a == b,
                "{} {mode:?}: the loaded scene renders differently",
                d.name
            );
        }
    }
}

#[test]
fn dump_scene_from_the_command_line_renders_the_same_bytes() {
    let dir = temp_dir("dump_cli");
    let json = dir.join("spheres.json");
    let small = [
        "--width",
        "24",
        "--height",
        "18",
        "--spp",
        "2",
        "--threads",
        "2",
    ];
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_host"))
            .args(args)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    let mut a = vec!["render", "spheres", "--dump-scene", json.to_str().unwrap()];
    a.extend(small);
    let stdout = run(&a);
    assert!(stdout.contains("wrote scene file"), "{stdout}");
    let a_png = dir.join("a.png");
    let b_png = dir.join("b.png");
    let mut a = vec!["render", "spheres", "--out", a_png.to_str().unwrap()];
    a.extend(small);
    run(&a);
    // The dump carries the settings the command would have used.
    run(&[
        "render",
        json.to_str().unwrap(),
        "--out",
        b_png.to_str().unwrap(),
    ]);
    assert_eq!(std::fs::read(a_png).unwrap(), std::fs::read(b_png).unwrap());
}

/// A small valid scene to break one field at a time.
fn base() -> Value {
    json!({
        "format": "raykernel-scene",
        "version": 1,
        "camera": {"eye": [0, 1, 4], "look_at": [0, 0, 0], "vfov_deg": 40},
        "materials": [
            {"name": "white", "diffuse": {"albedo": [0.7, 0.7, 0.7]}},
            {"name": "gold", "glossy": {"reflectance": [0.9, 0.7, 0.3], "exponent": 50}}
        ],
        "objects": [
            {"spheres": [{"center": [0, 0, 0], "radius": 1}], "material": "gold"},
            {"triangles": [[[-2, -1, -2], [-2, -1, 2], [2, -1, 2]]], "material": "white"}
        ],
        "lights": [{"point": {"position": [0, 3, 3], "intensity": [5, 5, 5]}}]
    })
}

fn load_text(text: &str) -> Result<SceneSpec, String> {
    parse_scene_file(text, Path::new("scene.json")).map_err(|e| e.to_string())
}

fn load_value(v: &Value) -> Result<SceneSpec, String> {
    load_text(&v.to_string())
}

fn broken(edit: impl FnOnce(&mut Value)) -> String {
    let mut v = base();
    edit(&mut v);
    load_value(&v).unwrap_err()
}

#[test]
fn a_minimal_scene_file_takes_defaults() {
    let s = load_value(&base()).unwrap();
    assert_eq!(s.name, "scene");
    assert_eq!(
        (s.settings.width, s.settings.height, s.settings.spp),
        (512, 512, 64)
    );
    assert_eq!(s.camera.up, [0.0, 1.0, 0.0]);
    assert_eq!(s.camera.aperture_radius, 0.0);
    assert!((s.camera.focus_distance - 17f32.sqrt()).abs() < 1e-6);
    assert_eq!(s.background, [0.0; 3]);
}

#[test]
fn bad_scene_files_name_the_file_the_field_and_the_problem() {
    let cases: Vec<(String, &str)> = vec![
        (
            load_text("{\"format\": \"raykernel-scene\", \"version\": 1, \"camera\": {")
                .unwrap_err(),
            "scene.json: EOF while parsing an object at line 1 column",
        ),
        (
            broken(|v| v["camera"]["fov"] = json!(40)),
            "scene.json: camera.fov: unknown field `fov`, expected one of `eye`, `look_at`",
        ),
        (
            broken(|v| v["objects"][0]["spheres"][0]["radius"] = json!(-1)),
            "scene.json: objects[0].spheres[0].radius: radius is negative",
        ),
        (
            broken(|v| v["objects"][0]["spheres"][0]["radius"] = json!("big")),
            "scene.json: objects[0].spheres[0].radius: invalid type: string \"big\", expected \
             f32 at line",
        ),
        (
            broken(|v| v["objects"][1]["material"] = json!("golf")),
            "scene.json: objects[1].material: no material named \"golf\" (materials: \"white\", \
             \"gold\")",
        ),
        (
            broken(|v| v["materials"][1]["glossy"]["reflectance"] = json!([0.9, 1.5, 0.3])),
            "scene.json: materials[1] (\"gold\").reflectance: must be at most 1",
        ),
        (
            broken(|v| v["materials"][1]["glossy"]["exponent"] = json!(0.5)),
            "scene.json: materials[1] (\"gold\").exponent: must lie in [1,",
        ),
        (
            broken(|v| v["materials"][0]["mirror"] = json!({"reflectance": [1, 1, 1]})),
            "scene.json: materials[0] (\"white\"): expected exactly one of `diffuse`, `mirror`, \
             `glossy`, `emissive`",
        ),
        (
            broken(|v| v["materials"][1]["name"] = json!("white")),
            "scene.json: materials[1] (\"white\"): duplicate name",
        ),
        (
            broken(|v| v["objects"][0]["mesh"] = json!("x.obj")),
            "scene.json: objects[0]: expected exactly one of `mesh`, `triangles`, `spheres`",
        ),
        (
            broken(|v| v["objects"][1]["mesh"] = json!("none.obj")),
            "scene.json: objects[1]: expected exactly one of",
        ),
        (
            broken(|v| {
                v["objects"][1] = json!({"mesh": "none.obj", "material": "white"});
            }),
            "scene.json: objects[1].mesh: none.obj: cannot read OBJ file",
        ),
        (
            broken(|v| v["objects"][0]["transform"] = json!({"scale": 2})),
            "scene.json: objects[0].transform: applies to `mesh` and `triangles` objects only",
        ),
        (
            broken(|v| v["objects"][1]["transform"] = json!({"scale": "x"})),
            "scene.json: objects[1].transform.scale: a number or an array of 3 numbers",
        ),
        (
            broken(|v| v["camera"]["vfov_deg"] = json!(180)),
            "scene.json: camera.vfov_deg: must lie in [0, 180]",
        ),
        (
            broken(|v| v["lights"][0] = json!({"spot": {}})),
            "scene.json: lights[0]: unknown variant `spot`, expected one of `point`, `rect`, \
             `sphere`",
        ),
        (
            broken(|v| v["lights"][0]["point"]["intensity"] = json!([1, -1, 1])),
            "scene.json: lights[0].intensity: must not be negative",
        ),
        (
            broken(|v| v["settings"] = json!({"spp": 0})),
            "scene.json: settings.spp: must be greater than zero",
        ),
        (
            broken(|v| v["settings"] = json!({"sampler": "halton"})),
            "scene.json: settings.sampler: unknown variant `halton`, expected one of \
             `independent`, `stratified`, `sobol`",
        ),
        (
            broken(|v| v["background"] = json!([0, 0])),
            "scene.json: background: invalid length 2, expected an array of length 3",
        ),
        (
            broken(|v| v["version"] = json!(2)),
            "scene.json: version: this reader reads version 1, found 2",
        ),
        (
            broken(|v| v["format"] = json!("pbrt")),
            "scene.json: format: expected \"raykernel-scene\", found \"pbrt\"",
        ),
        (
            broken(|v| {
                v.as_object_mut().unwrap().remove("materials");
            }),
            "scene.json: missing field `materials`",
        ),
    ];
    for (got, want) in cases {
        assert!(got.starts_with(want), "expected {want:?}\n     got {got:?}");
        assert!(!got.contains('\n'), "one line: {got:?}");
    }
}

#[test]
fn fixed_point_range_errors_name_the_field() {
    let mut v = base();
    v["objects"][1]["triangles"][0][2] = json!([9000, -1, 2]);
    let spec = load_value(&v).unwrap();
    let o = RenderOptions {
        mode: Mode::Fixed,
        ..RenderOptions::default()
    };
    let Err(host::render::RenderError::Scene(e)) = render(&spec.data(), spec.settings, &o) else {
        panic!("fixed mode accepted a coordinate of 9000");
    };
    assert_eq!(
        spec.explain(&e, "fixed").to_string(),
        "scene.json: objects[1].triangles[0][2]: coordinate outside the fixed-point range \
         [-8192, 8192] (in fixed mode)"
    );
}

#[test]
fn bad_files_fail_from_the_command_line_with_one_message() {
    let dir = temp_dir("scene_file_cli");
    let bad = dir.join("bad.json");
    let mut v = base();
    v["materials"][1]["glossy"]["reflectance"] = json!([2, 0, 0]);
    std::fs::write(&bad, v.to_string()).unwrap();
    let missing = dir.join("missing.json");
    for (path, needle) in [
        (
            &bad,
            "bad.json: materials[1] (\"gold\").reflectance: must be at most 1",
        ),
        (&missing, "missing.json: cannot read: "),
    ] {
        for cmd in ["render", "check"] {
            let mut args = vec![cmd, path.to_str().unwrap()];
            if cmd == "render" {
                args.extend(["--out", "x.png"]);
            }
            let out = Command::new(env!("CARGO_BIN_EXE_host"))
                .args(&args)
                .output()
                .unwrap();
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(1), "{stderr}");
            assert_eq!(stderr.lines().count(), 1, "{stderr}");
            assert!(
                stderr.starts_with("error: ") && stderr.contains(needle),
                "{stderr}"
            );
            assert!(out.stdout.is_empty());
        }
    }
}

#[test]
fn built_in_names_resolve_and_unknown_ones_do_not() {
    for d in scenes::ALL {
        assert_eq!(resolve_scene(d.name).unwrap().data(), d);
    }
    let e = resolve_scene("nope").unwrap_err().to_string();
    assert!(e.contains("unknown scene `nope`"), "{e}");
}
