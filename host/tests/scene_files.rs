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
        let out = Command::new(env!("CARGO_BIN_EXE_raykernel"))
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
            "scene.json: camera.vfov_deg: must lie strictly between 0 and 180 degrees",
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
        "scene.json: objects[1].triangles[0][2]: coordinate outside [-8192, 8192], the \
         coordinate range of fixed mode"
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
            let out = Command::new(env!("CARGO_BIN_EXE_raykernel"))
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

/// A closed box of six mirror walls (reflectance `r`) around the camera, no lights.
fn mirror_box(r: f32, max_depth: u64) -> Value {
    let quad = |a: [i32; 3], b: [i32; 3], c: [i32; 3], d: [i32; 3]| {
        vec![json!([a, b, c]), json!([a, c, d])]
    };
    let (l, h) = (-1, 1);
    let mut tris = Vec::new();
    tris.extend(quad([l, l, l], [h, l, l], [h, h, l], [l, h, l]));
    tris.extend(quad([l, l, h], [h, l, h], [h, h, h], [l, h, h]));
    tris.extend(quad([l, l, l], [l, h, l], [l, h, h], [l, l, h]));
    tris.extend(quad([h, l, l], [h, h, l], [h, h, h], [h, l, h]));
    tris.extend(quad([l, l, l], [h, l, l], [h, l, h], [l, l, h]));
    tris.extend(quad([l, h, l], [h, h, l], [h, h, h], [l, h, h]));
    json!({
        "format": "raykernel-scene",
        "version": 1,
        "camera": {"eye": [0.1, 0.2, 0.3], "look_at": [0.5, 0.4, -1], "vfov_deg": 40},
        "settings": {"width": 2, "height": 1, "spp": 1, "max_depth": max_depth},
        "materials": [{"name": "mirror", "mirror": {"reflectance": [r, r, r]}}],
        "objects": [{"triangles": tris, "material": "mirror"}]
    })
}

#[test]
fn a_closed_mirror_box_stops_bouncing_once_the_path_weight_is_spent() {
    // 0.9 per bounce: the weight leaves f32's normal range after about 830 bounces, and a
    // subnormal weight times 0.9 can round back to itself, so only the weight test ends it.
    let spec = load_value(&mirror_box(0.9, 100_000)).unwrap();
    for mode in [Mode::F32, Mode::Fixed] {
        let o = RenderOptions {
            mode,
            ..RenderOptions::default()
        };
        let r = render(&spec.data(), spec.settings, &o).unwrap();
        let per_path = r.stats.reflection_rays / r.stats.camera_rays;
        assert!(
            (700..=1000).contains(&per_path),
            "{mode:?}: {per_path} bounces per path"
        );
    }
    // A scene file asking for more bounces than the bound is refused before rendering.
    let e = host::cli::check_render_request(&spec, Mode::F32, false)
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "scene.json: settings.max_depth: 100000 bounces; the limit is 64"
    );
}

#[test]
fn scene_files_asking_for_too_much_fail_with_the_real_limit_before_allocating() {
    let request = |edit: &dyn Fn(&mut Value)| {
        let mut v = base();
        edit(&mut v);
        let spec = load_value(&v).unwrap();
        host::cli::check_render_request(&spec, Mode::F32, false)
            .unwrap_err()
            .to_string()
    };
    for (settings, want) in [
        (
            json!({"width": 4294967295u32, "height": 1}),
            "scene.json: settings.width: 4294967295 is more than the limit of 65536 pixels",
        ),
        (
            json!({"width": 40000, "height": 40000}),
            "scene.json: settings: 40000 × 40000 = 1600000000 pixels; the limit is width × \
             height ≤ 67108864 (8192 × 8192)",
        ),
        (
            json!({"spp": 4294967295u32}),
            "scene.json: settings.spp: 4294967295 samples per pixel; the limit is 1048576",
        ),
        (
            json!({"max_depth": 4294967295u32}),
            "scene.json: settings.max_depth: 4294967295 bounces; the limit is 64",
        ),
    ] {
        assert_eq!(request(&|v| v["settings"] = settings.clone()), want);
    }
    // From the command line: the same limit, at once (no render, no allocation).
    let dir = temp_dir("scene_limits_cli");
    let big = dir.join("big.json");
    let mut v = base();
    v["settings"] = json!({"width": 40000, "height": 40000});
    std::fs::write(&big, v.to_string()).unwrap();
    let png = dir.join("big.png");
    for args in [
        vec![
            "render",
            big.to_str().unwrap(),
            "--out",
            png.to_str().unwrap(),
        ],
        vec!["check", big.to_str().unwrap()],
        vec![
            "render",
            "--width",
            "16384",
            "--height",
            "16384",
            "--out",
            png.to_str().unwrap(),
        ],
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_raykernel"))
            .args(&args)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(stderr.contains("width × height ≤ 67108864"), "{stderr}");
        assert!(!png.exists(), "no output file is left behind");
    }
}

#[test]
fn camera_messages_name_the_real_problem() {
    let fails = |edit: &dyn Fn(&mut Value), mode: Mode| {
        let mut v = base();
        edit(&mut v);
        match load_value(&v) {
            Err(e) => e,
            Ok(spec) => host::cli::check_render_request(&spec, mode, false)
                .unwrap_err()
                .to_string(),
        }
    };
    for vfov in [0, 180] {
        let e = fails(&|v| v["camera"]["vfov_deg"] = json!(vfov), Mode::F32);
        assert_eq!(
            e,
            "scene.json: camera.vfov_deg: must lie strictly between 0 and 180 degrees (both \
             excluded): the full vertical field of view"
        );
    }
    let e = fails(&|v| v["camera"]["look_at"] = json!([0, 1, 4]), Mode::F32);
    assert!(
        e.starts_with("scene.json: camera.look_at: equals `eye`"),
        "{e}"
    );
    let e = fails(&|v| v["camera"]["eye"] = json!([1e20, 0, 0]), Mode::F32);
    assert!(
        e.starts_with(
            "scene.json: camera.eye: [1e20, 0.0, 0.0] lies outside [-1099511627776, \
             1099511627776], the coordinate range of f32 mode"
        ),
        "{e}"
    );
    // Fine in f32; in fixed mode no camera ray could start there (the image would be blank).
    let e = fails(&|v| v["camera"]["eye"] = json!([0, 1, 9000]), Mode::Fixed);
    assert!(
        e.starts_with(
            "scene.json: camera.eye: [0.0, 1.0, 9000.0] lies outside [-8192, 8192], the \
             coordinate range of fixed mode: no camera ray can start there"
        ),
        "{e}"
    );
    let mut v = base();
    v["camera"]["eye"] = json!([0, 1, 9000]);
    let spec = load_value(&v).unwrap();
    assert!(host::cli::check_render_request(&spec, Mode::F32, false).is_ok());
}

#[test]
fn range_messages_name_the_mode_and_the_sphere() {
    let mut v = base();
    v["lights"] =
        json!([{"sphere": {"center": [8191, 0, 0], "radius": 10, "radiance": [1, 1, 1]}}]);
    let spec = load_value(&v).unwrap();
    let e = host::cli::check_render_request(&spec, Mode::Fixed, false)
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "scene.json: lights[0].radius: the sphere (centre ± radius) reaches outside [-8192, \
         8192], the coordinate range of fixed mode: every point of it must lie inside (move \
         it inwards or make it smaller)"
    );
    // A huge coordinate in f32 mode names f32's range, never fixed point.
    let mut v = base();
    v["objects"][1]["triangles"][0][2] = json!([1e30, -1, 2]);
    let e = load_value(&v).unwrap_err();
    assert!(!e.contains("fixed"), "{e}");
    assert!(e.contains("the coordinate range of f32 mode"), "{e}");
}

#[test]
fn json_that_is_not_an_object_says_so_without_type_names() {
    for (text, what) in [
        ("[1, 2]", "an array"),
        ("\"raykernel-scene\"", "a string"),
        ("42", "a number"),
        ("null", "null"),
    ] {
        let e = load_text(text).unwrap_err();
        assert_eq!(
            e,
            format!(
                "scene.json: a scene file is one JSON object `{{ ... }}`, but this file holds \
                 {what}"
            )
        );
    }
    let e = broken(|v| v["camera"] = json!(5));
    assert!(!e.contains("struct"), "{e}");
    assert!(e.contains("expected a JSON object"), "{e}");
}

#[test]
fn huge_and_binary_strings_are_never_echoed_whole_or_raw() {
    let dir = temp_dir("scene_huge_string");
    let path = dir.join("huge.json");
    let mut v = base();
    v["camera"][format!("\u{1b}[2J{}", "k".repeat(5 << 20))] = json!(1);
    std::fs::write(&path, v.to_string()).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_raykernel"))
        .args(["render", path.to_str().unwrap(), "--explain"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr.len() < 1000, "{} bytes", stderr.len());
    assert!(stderr.contains("unknown field"), "{stderr}");
    assert!(stderr.contains("[… 5242827 characters …]"), "{stderr}");
    assert!(!stderr.contains('\u{1b}'), "{stderr}");
}

#[test]
fn a_byte_order_mark_is_accepted_in_scene_and_camera_files() {
    let text = format!("\u{feff}{}", base());
    let with = load_text(&text).unwrap();
    assert_eq!(with, load_value(&base()).unwrap());
    let dir = temp_dir("scene_bom");
    let path = dir.join("bom.json");
    std::fs::write(&path, &text).unwrap();
    assert_eq!(load_scene_file(&path).unwrap().triangles, with.triangles);
    let obj = dir.join("tri.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    std::fs::write(
        dir.join("tri.camera"),
        "\u{feff}eye 0 0 5\ntarget 0 0 0\nup 0 1 0\nvfov 30\n",
    )
    .unwrap();
    let spec = resolve_scene(obj.to_str().unwrap()).unwrap();
    assert_eq!(spec.camera.eye, [0.0, 0.0, 5.0]);
    assert_eq!(spec.camera.vfov_deg, 30.0);
}

#[test]
fn many_materials_load_and_lists_are_bounded() {
    let mut v = base();
    let materials: Vec<Value> = (0..40_000)
        .map(|i| json!({"name": format!("m{i}"), "diffuse": {"albedo": [0.5, 0.5, 0.5]}}))
        .collect();
    v["materials"] = Value::Array(materials);
    v["objects"][0]["material"] = json!("m39999");
    v["objects"][1]["material"] = json!("m0");
    let start = std::time::Instant::now();
    let spec = load_value(&v).unwrap();
    println!("40000 materials loaded in {:?}", start.elapsed());
    assert_eq!(spec.objects[0].material, 39_999);
    let names = v["materials"].as_array_mut().unwrap();
    names.push(json!({"name": "m5", "diffuse": {"albedo": [0.5, 0.5, 0.5]}}));
    let e = load_value(&v).unwrap_err();
    assert!(
        e.contains("materials[40000] (\"m5\"): duplicate name"),
        "{e}"
    );
    let mut v = base();
    v["objects"][1]["material"] = json!("nope");
    let mut many: Vec<Value> = (0..70_000)
        .map(|i| json!({"name": format!("m{i}"), "diffuse": {"albedo": [0.5, 0.5, 0.5]}}))
        .collect();
    many.truncate(65_537);
    v["materials"] = Value::Array(many);
    let e = load_value(&v).unwrap_err();
    assert_eq!(
        e,
        "scene.json: materials: 65537 materials; the limit is 65536"
    );
}

#[test]
fn special_files_as_mesh_paths_fail_fast_with_what_they_are() {
    let dir = temp_dir("scene_special_mesh");
    let mut paths = vec![
        ("/dev/zero".to_string(), "is a device, not a regular file"),
        (
            dir.display().to_string(),
            "is a directory, not a regular file",
        ),
    ];
    let fifo = dir.join("pipe.obj");
    let made = fifo.exists()
        || Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .is_ok_and(|s| s.success());
    if made {
        paths.push((
            fifo.display().to_string(),
            "is a named pipe, not a regular file",
        ));
    } else {
        println!("skipped: named pipe as a mesh path (mkfifo unavailable)");
    }
    for (path, want) in paths {
        let e = broken(|v| v["objects"][1] = json!({"mesh": path, "material": "white"}));
        assert!(e.starts_with("scene.json: objects[1].mesh: "), "{e}");
        assert!(e.ends_with(want), "{e}");
    }
}

#[test]
fn dump_of_an_obj_names_the_mesh_and_the_real_focus_and_renders_the_same_bytes() {
    let dir = temp_dir("dump_obj");
    std::fs::create_dir_all(dir.join("meshes")).unwrap();
    std::fs::create_dir_all(dir.join("out")).unwrap();
    let obj = dir.join("meshes/ball.obj");
    std::fs::write(&obj, common::icosphere([0.0; 3], 1.0, 2).to_obj()).unwrap();
    let json = dir.join("out/ball.json");
    let camera = [
        "--eye",
        "0,1,6",
        "--look-at",
        "0,0,0",
        "--vfov",
        "35",
        "--aperture",
        "0.05",
    ];
    let small = [
        "--width",
        "20",
        "--height",
        "16",
        "--spp",
        "2",
        "--threads",
        "2",
    ];
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_raykernel"))
            .args(args)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    let (a_png, b_png) = (dir.join("a.png"), dir.join("b.png"));
    let mut a = vec![
        "render",
        obj.to_str().unwrap(),
        "--out",
        a_png.to_str().unwrap(),
    ];
    a.extend(camera);
    a.extend(small);
    a.extend(["--dump-scene", json.to_str().unwrap()]);
    run(&a);
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["objects"][0]["mesh"], "../meshes/ball.obj");
    assert!(v["objects"][0].get("triangles").is_none());
    let c = &v["camera"];
    assert_eq!(
        (c["eye"].clone(), c["vfov_deg"].clone()),
        (json!([0.0, 1.0, 6.0]), json!(35.0))
    );
    assert_eq!(c["aperture_radius"], json!(0.05));
    let focus = c["focus_distance"].as_f64().unwrap();
    assert!((focus - 37f64.sqrt()).abs() < 1e-6, "{focus}");
    run(&[
        "render",
        json.to_str().unwrap(),
        "--out",
        b_png.to_str().unwrap(),
    ]);
    assert_eq!(std::fs::read(a_png).unwrap(), std::fs::read(b_png).unwrap());
    // Without camera flags the framed camera's focus is its distance to the target, not 1.
    run(&[
        "render",
        obj.to_str().unwrap(),
        "--dump-scene",
        json.to_str().unwrap(),
    ]);
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let c = &v["camera"];
    let eye: Vec<f64> = serde_json::from_value(c["eye"].clone()).unwrap();
    let at: Vec<f64> = serde_json::from_value(c["look_at"].clone()).unwrap();
    let d = (0..3).map(|k| (eye[k] - at[k]).powi(2)).sum::<f64>().sqrt();
    let focus = c["focus_distance"].as_f64().unwrap();
    assert!(
        (focus - d).abs() < 1e-4 * d && d > 2.0,
        "focus {focus}, eye to look_at {d}"
    );
}

#[test]
fn integrator_and_emission_keys_load_dump_and_render_the_same_bytes() {
    use raykernel::render::Integrator;
    let mut v = base();
    v["settings"] = json!({"integrator": "path", "max_path_length": 7, "width": 16,
                           "height": 12, "spp": 2});
    v["objects"][1]["emission"] = json!([0.5, 0.25, 0.0]);
    let spec = load_value(&v).unwrap();
    assert_eq!(spec.settings.integrator, Integrator::Path { max_length: 7 });
    assert_eq!(spec.objects[1].emission, [0.5, 0.25, 0.0]);
    // Without a length the path integrator takes the default; `direct` drops it.
    v["settings"] = json!({"integrator": "path"});
    let spec = load_value(&v).unwrap();
    assert_eq!(spec.settings.integrator, Integrator::Path { max_length: 5 });
    v["settings"] = json!({"integrator": "direct", "max_path_length": 3});
    assert_eq!(
        load_value(&v).unwrap().settings.integrator,
        Integrator::Direct
    );
    // A path scene round-trips through a file, bit for bit, and renders the same bytes.
    let d = SceneData {
        settings: Settings {
            width: 16,
            height: 12,
            spp: 2,
            integrator: Integrator::Path { max_length: 4 },
            ..scenes::CORNELL.settings
        },
        ..scenes::CORNELL
    };
    let text = dump(&d, &[]);
    assert!(text.contains("\"integrator\": \"path\""), "{text}");
    let loaded = parse_scene_file(&text, Path::new("cornell.json")).unwrap();
    assert_eq!(loaded.data(), d);
    for mode in [Mode::F32, Mode::Fixed] {
        assert!(srgb(&d, d.settings, mode) == srgb(&loaded.data(), loaded.settings, mode));
    }
    // Bad values name the field.
    let e = broken(|v| v["settings"] = json!({"integrator": "photon"}));
    assert!(e.contains("integrator"), "{e}");
    let e = broken(|v| v["objects"][0]["emission"] = json!([-1, 0, 0]));
    assert!(e.contains("emission"), "{e}");
}

#[test]
fn one_sided_key_loads_dumps_and_defaults_to_two_sided() {
    let mut v = base();
    assert!(!load_value(&v).unwrap().objects[0].one_sided);
    v["objects"][0]["one_sided"] = json!(true);
    let spec = load_value(&v).unwrap();
    assert!(spec.objects[0].one_sided);
    assert!(!spec.objects[1].one_sided);
    // A one-sided object round-trips; two-sided ones write no key.
    let mut objects = scenes::CORNELL.objects.to_vec();
    objects[0].one_sided = true;
    let d = SceneData {
        objects: &objects,
        ..scenes::CORNELL
    };
    let text = dump(&d, &[]);
    assert_eq!(text.matches("\"one_sided\"").count(), 1, "{text}");
    let loaded = parse_scene_file(&text, Path::new("cornell.json")).unwrap();
    assert_eq!(loaded.data(), d);
    let e = broken(|v| v["objects"][0]["one_sided"] = json!("yes"));
    assert!(e.contains("one_sided"), "{e}");
}

#[test]
fn gaussian_filter_keys_load_dump_and_default() {
    use raykernel::render::Filter;
    let mut v = base();
    v["settings"] = json!({"filter": "gaussian", "filter_sigma": 0.7, "filter_radius": 2.0});
    let spec = load_value(&v).unwrap();
    assert_eq!(
        spec.settings.filter,
        Filter::Gaussian {
            sigma: 0.7,
            radius: 2.0
        }
    );
    // Without parameters the defaults; other filters ignore them.
    v["settings"] = json!({"filter": "gaussian"});
    assert_eq!(
        load_value(&v).unwrap().settings.filter,
        Filter::Gaussian {
            sigma: host::scenefile::DEFAULT_FILTER_SIGMA,
            radius: host::scenefile::DEFAULT_FILTER_RADIUS
        }
    );
    v["settings"] = json!({"filter": "tent", "filter_sigma": 0.7});
    assert_eq!(load_value(&v).unwrap().settings.filter, Filter::Tent);
    // A Gaussian scene round-trips through a file and renders the same bytes.
    let d = SceneData {
        settings: Settings {
            width: 16,
            height: 12,
            spp: 2,
            filter: Filter::Gaussian {
                sigma: 0.4,
                radius: 1.25,
            },
            ..scenes::SPHERES.settings
        },
        ..scenes::SPHERES
    };
    let text = dump(&d, &[]);
    assert!(text.contains("\"filter_sigma\": 0.4"), "{text}");
    let loaded = parse_scene_file(&text, Path::new("spheres.json")).unwrap();
    assert_eq!(loaded.data(), d);
    for mode in [Mode::F32, Mode::Fixed] {
        assert!(srgb(&d, d.settings, mode) == srgb(&loaded.data(), loaded.settings, mode));
    }
}
