//! The formats users bring and expect: OBJ with MTL colours, glTF 2.0 scenes, OpenEXR output.
//! The fixtures are committed (docs/scenes, host/tests/fixtures); the conversion of a shared
//! mesh to `.glb` by `host/scripts/obj_to_glb.py` is ignored by default ("needs ../shared").

use clap::Parser;
use host::cli::{run_render, Cli, Command};
use host::obj::load_obj;
use host::render::RenderOptions;
use host::scene::{obj_scene, resolve_scene, OBJ_ALBEDO};
use host::scenefile::{dump, load_scene_file, scene_file_text, spec_to_scene_file};
use host::spec::SceneSpec;
use raykernel::render::scenes::{ShapeRange, SphereData};
use raykernel::render::{Light, Material, Settings};
use std::path::{Path, PathBuf};

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(rel)
}

fn temp_dir(name: &str) -> PathBuf {
    raykernel_testkit::empty_dir(
        Path::new(env!("CARGO_TARGET_TMPDIR"))
            .join("formats")
            .join(name),
    )
}

/// Runs `render` with these arguments (after the subcommand).
fn render(args: &[&str]) -> Result<host::cli::RenderReport, host::Error> {
    let cli = Cli::try_parse_from(["raykernel", "render"].iter().chain(args)).unwrap();
    let Command::Render(r) = cli.command else {
        unreachable!("parsed a render command")
    };
    run_render(&r)
}

/// The triangles of object `i` of a scene.
fn object_triangles(spec: &SceneSpec, i: usize) -> &[[[f32; 3]; 3]] {
    let ShapeRange::Triangles { first, count } = spec.objects[i].shape else {
        panic!("object {i} is not a triangle mesh")
    };
    &spec.triangles[first as usize..(first + count) as usize]
}

fn read_png(path: &Path) -> (u32, u32, Vec<u8>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

// --- OBJ + MTL -------------------------------------------------------------------------------

#[test]
fn obj_groups_get_their_mtl_colours() {
    let obj = repo("docs/scenes/cubes.obj");
    let spec = obj_scene(&obj).unwrap();
    assert_eq!(spec.material_names, ["floor", "red", "teal", "lamp"]);
    assert_eq!(
        spec.materials,
        [
            Material::Diffuse {
                albedo: [0.7, 0.7, 0.68]
            },
            Material::Diffuse {
                albedo: [0.75, 0.12, 0.1]
            },
            Material::Diffuse {
                albedo: [0.1, 0.5, 0.55]
            },
            Material::Emissive {
                radiance: [4.0, 3.6, 3.0]
            },
        ]
    );
    // One object per material, holding exactly that group's faces in file order.
    let mesh = load_obj(&obj).unwrap();
    let tri =
        |range: std::ops::Range<usize>| -> Vec<_> { range.map(|t| mesh.triangle_f32(t)).collect() };
    let groups = [tri(0..2), tri(2..14), tri(14..26), tri(26..28)];
    assert_eq!(spec.objects.len(), 4);
    for (i, group) in groups.iter().enumerate() {
        assert_eq!(spec.objects[i].material, i as u32);
        assert_eq!(object_triangles(&spec, i), group.as_slice(), "object {i}");
    }
    assert_eq!(spec.triangles.len(), mesh.triangle_count());
}

#[test]
fn mtl_colours_reach_the_image() {
    let dir = temp_dir("mtl_image");
    let out = dir.join("cubes.png");
    let obj = repo("docs/scenes/cubes.obj");
    render(&[
        obj.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--width",
        "48",
        "--height",
        "48",
        "--spp",
        "4",
    ])
    .unwrap();
    let (_, _, rgb) = read_png(&out);
    let px: Vec<[u32; 3]> = rgb
        .chunks_exact(3)
        .map(|p| [p[0], p[1], p[2]].map(u32::from))
        .collect();
    let red = px
        .iter()
        .filter(|p| p[0] > 60 && p[0] > 2 * p[1].max(p[2]))
        .count();
    let teal = px.iter().filter(|p| p[2] > 40 && p[2] > 2 * p[0]).count();
    assert!(red > 20 && teal > 20, "red {red}, teal {teal} pixels");
}

#[test]
fn obj_without_material_statements_stays_white() {
    let spec = obj_scene(&repo("docs/scenes/tetra.obj")).unwrap();
    assert_eq!(spec.materials, [Material::Diffuse { albedo: OBJ_ALBEDO }]);
    assert_eq!(spec.objects.len(), 1);
}

#[test]
fn faces_before_the_first_usemtl_are_white_and_bad_references_name_their_line() {
    let dir = temp_dir("mtl_errors");
    std::fs::write(dir.join("m.mtl"), "newmtl blue\nKd 0 0 1\n").unwrap();
    let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let good = dir.join("good.obj");
    std::fs::write(
        &good,
        format!("mtllib m.mtl\n{tri}f 1 2 3\nusemtl blue\nf 1 3 2\n"),
    )
    .unwrap();
    let spec = obj_scene(&good).unwrap();
    assert_eq!(
        spec.materials,
        [
            Material::Diffuse { albedo: OBJ_ALBEDO },
            Material::Diffuse {
                albedo: [0.0, 0.0, 1.0]
            },
        ]
    );
    for (name, text, needle) in [
        (
            "unknown.obj",
            format!("mtllib m.mtl\n{tri}usemtl red\nf 1 2 3\n"),
            "unknown.obj:5: `usemtl red`: no such material in m.mtl",
        ),
        (
            "nolib.obj",
            format!("{tri}usemtl red\nf 1 2 3\n"),
            "nolib.obj:4: `usemtl red`: no such material",
        ),
        (
            "missing.obj",
            format!("mtllib gone.mtl\n{tri}f 1 2 3\n"),
            "gone.mtl: cannot read MTL file",
        ),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        let e = obj_scene(&path).unwrap_err().to_string();
        assert!(e.contains(needle), "{name}: {e}");
    }
    std::fs::write(dir.join("bad.mtl"), "newmtl x\nKd 2 0 0\n").unwrap();
    let path = dir.join("badlib.obj");
    std::fs::write(&path, format!("mtllib bad.mtl\n{tri}usemtl x\nf 1 2 3\n")).unwrap();
    let e = obj_scene(&path).unwrap_err().to_string();
    assert!(
        e.contains("bad.mtl:2: `Kd` values must lie in [0, 1]"),
        "{e}"
    );
}

// --- smooth shading from `vn` ------------------------------------------------------------

/// An icosphere of `levels` subdivisions as OBJ text, with its unit positions as `vn` normals
/// when `normals`.
fn icosphere_obj(levels: u32, normals: bool) -> String {
    let (positions, faces) = raykernel_testkit::icosphere::unit_icosphere(levels);
    let mut text = String::new();
    for p in &positions {
        text.push_str(&format!("v {} {} {}\n", p[0], p[1], p[2]));
        if normals {
            text.push_str(&format!("vn {} {} {}\n", p[0], p[1], p[2]));
        }
    }
    for f in &faces {
        let [a, b, c] = f.map(|i| i + 1);
        if normals {
            text.push_str(&format!("f {a}//{a} {b}//{b} {c}//{c}\n"));
        } else {
            text.push_str(&format!("f {a} {b} {c}\n"));
        }
    }
    text
}

fn render_linear(spec: &SceneSpec, settings: Settings) -> Vec<[f32; 3]> {
    let options = RenderOptions {
        threads: 2,
        ..RenderOptions::default()
    };
    match host::render::render(&spec.data(), settings, &options) {
        Ok(r) => r.frame.linear,
        Err(e) => panic!("render failed: {e:?}"),
    }
}

/// An icosphere with its `vn` normals renders as the sphere it approximates: inside the
/// silhouette, its image is much closer to an exact sphere's than the flat-shaded (faceted)
/// mesh's is.
#[test]
fn obj_vertex_normals_render_without_facets() {
    let dir = temp_dir("smooth");
    let (smooth_obj, flat_obj) = (dir.join("smooth.obj"), dir.join("flat.obj"));
    std::fs::write(&smooth_obj, icosphere_obj(3, true)).unwrap();
    std::fs::write(&flat_obj, icosphere_obj(3, false)).unwrap();
    let smooth = obj_scene(&smooth_obj).unwrap();
    let flat = obj_scene(&flat_obj).unwrap();
    assert_eq!(smooth.triangles, flat.triangles);
    assert_eq!(smooth.vertex_normals.len(), smooth.triangles.len());
    assert!(flat.vertex_normals.is_empty());
    // The exact sphere under the same camera and lights.
    // One point light, one sample at each pixel's centre: no noise, only shading differs.
    let lights = vec![Light::Point {
        position: [3.0, 4.0, 5.0],
        intensity: [40.0; 3],
    }];
    let (mut smooth, mut flat) = (smooth, flat);
    smooth.lights.clone_from(&lights);
    flat.lights = lights;
    let mut sphere = flat.clone();
    sphere.spheres = vec![SphereData {
        center: [0.0; 3],
        radius: 1.0,
    }];
    sphere.objects[0].shape = ShapeRange::Spheres { first: 0, count: 1 };
    let settings = Settings {
        width: 96,
        height: 96,
        spp: 1,
        ..flat.settings
    };
    let images = [&smooth, &flat, &sphere].map(|s| render_linear(s, settings));
    let background = flat.background;
    let (w, h) = (96usize, 96usize);
    // Pixels inside every silhouette: the pixel and its four neighbours show the object.
    let on_object = |x: usize, y: usize| images.iter().all(|im| im[y * w + x] != background);
    let interior: Vec<usize> = (1..h - 1)
        .flat_map(|y| (1..w - 1).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            on_object(x, y)
                && on_object(x - 1, y)
                && on_object(x + 1, y)
                && on_object(x, y - 1)
                && on_object(x, y + 1)
        })
        .map(|(x, y)| y * w + x)
        .collect();
    assert!(interior.len() > 1500, "{} interior pixels", interior.len());
    let error = |im: &[[f32; 3]]| {
        interior
            .iter()
            .map(|&i| {
                (0..3)
                    .map(|c| f64::from((im[i][c] - images[2][i][c]).abs()))
                    .sum::<f64>()
            })
            .sum::<f64>()
            / interior.len() as f64
    };
    let (smooth_error, flat_error) = (error(&images[0]), error(&images[1]));
    assert!(
        smooth_error < 0.3 * flat_error,
        "mean error against the exact sphere: smooth {smooth_error}, flat {flat_error}"
    );
}

/// Normals survive a scene dump: a mesh object names its OBJ file (the normals come from its
/// `vn` again), inline triangles carry `vertex_normals`; both load to the same scene.
#[test]
fn vertex_normals_survive_a_scene_dump() {
    let dir = temp_dir("smooth_dump");
    let obj = dir.join("ball.obj");
    std::fs::write(&obj, icosphere_obj(1, true)).unwrap();
    let spec = obj_scene(&obj).unwrap();
    let file = dir.join("ball.json");
    let text = scene_file_text(&spec_to_scene_file(&spec, &file));
    assert!(text.contains("\"mesh\""), "{text}");
    std::fs::write(&file, &text).unwrap();
    assert_eq!(
        load_scene_file(&file).unwrap().vertex_normals,
        spec.vertex_normals
    );
    let inline = dir.join("inline.json");
    let text = dump(&spec.data(), &spec.material_names);
    assert!(text.contains("\"vertex_normals\""));
    std::fs::write(&inline, &text).unwrap();
    let back = load_scene_file(&inline).unwrap();
    assert_eq!(back.vertex_normals, spec.vertex_normals);
    assert_eq!(back.triangles, spec.triangles);
}

#[test]
fn inline_vertex_normals_need_one_entry_per_triangle() {
    let dir = temp_dir("smooth_inline");
    let file = dir.join("bad.json");
    let text = r#"{
        "format": "raykernel-scene", "version": 1,
        "camera": {"eye": [0, 0, 5], "look_at": [0, 0, 0], "up": [0, 1, 0],
                   "vfov_deg": 40, "aperture_radius": 0, "focus_distance": 5},
        "materials": [{"name": "white", "diffuse": {"albedo": [0.8, 0.8, 0.8]}}],
        "objects": [{"material": "white",
                     "triangles": [[[0, 0, 0], [1, 0, 0], [0, 1, 0]]],
                     "vertex_normals": []}],
        "lights": []
    }"#;
    std::fs::write(&file, text).unwrap();
    let e = load_scene_file(&file).unwrap_err().to_string();
    assert!(
        e.contains("objects[0].vertex_normals: 0 entries for 1 triangles"),
        "{e}"
    );
}

// --- glTF ------------------------------------------------------------------------------------

#[test]
fn gltf_of_an_obj_is_the_same_scene_and_image() {
    let obj = repo("docs/scenes/tetra.obj");
    let glb = repo("host/tests/fixtures/tetra.glb");
    let (a, b) = (
        obj_scene(&obj).unwrap(),
        resolve_scene(glb.to_str().unwrap()).unwrap(),
    );
    assert_eq!(a.triangles, b.triangles);
    assert_eq!(a.materials, b.materials);
    assert_eq!(a.lights, b.lights);
    assert_eq!(a.camera, b.camera);
    assert_eq!(a.settings, b.settings);
    let dir = temp_dir("gltf_same_image");
    let png = |scene: &Path, name: &str| {
        let out = dir.join(name);
        render(&[
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--width",
            "32",
            "--height",
            "32",
            "--spp",
            "4",
        ])
        .unwrap();
        read_png(&out)
    };
    assert_eq!(png(&obj, "obj.png"), png(&glb, "glb.png"));
}

#[test]
fn gltf_node_transform_material_and_camera_are_used() {
    let glb = repo("host/tests/fixtures/tetra_placed.glb");
    let spec = resolve_scene(glb.to_str().unwrap()).unwrap();
    let mesh = load_obj(&repo("docs/scenes/tetra.obj")).unwrap();
    // The node scales by 2 and translates by (0, 1, 0): exact in f32 for these vertices.
    let expected: Vec<_> = (0..mesh.triangle_count())
        .map(|t| {
            mesh.triangle_f32(t)
                .map(|p| [2.0 * p[0], 2.0 * p[1] + 1.0, 2.0 * p[2]])
        })
        .collect();
    assert_eq!(spec.triangles, expected);
    assert_eq!(
        spec.materials,
        [Material::Diffuse {
            albedo: [0.2, 0.5, 0.8]
        }]
    );
    // The camera node: eye (3, 2.5, 6) looking at (0, 1, 0), 35 degrees.
    let c = spec.camera;
    let close = |a: [f32; 3], b: [f32; 3]| (0..3).all(|k| (a[k] - b[k]).abs() < 1e-5);
    assert!(close(c.eye, [3.0, 2.5, 6.0]), "{c:?}");
    let dir = |p: [f32; 3]| {
        let d: Vec<f32> = (0..3).map(|k| p[k] - c.eye[k]).collect();
        let n = d.iter().map(|x| x * x).sum::<f32>().sqrt();
        [d[0] / n, d[1] / n, d[2] / n]
    };
    assert!(close(dir(c.look_at), dir([0.0, 1.0, 0.0])), "{c:?}");
    assert!((c.vfov_deg - 35.0).abs() < 1e-4, "{c:?}");
}

#[test]
fn malformed_gltf_is_an_error_never_a_panic() {
    let bytes = std::fs::read(repo("host/tests/fixtures/tetra_placed.glb")).unwrap();
    let dir = temp_dir("gltf_mutations");
    let path = dir.join("m.glb");
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let (mut ok, mut errors) = (0, 0);
    for round in 0..600 {
        let mut m = bytes.clone();
        match round % 3 {
            // Overwrite a few bytes anywhere (JSON, lengths, binary data).
            0 => {
                for _ in 0..1 + next() % 4 {
                    let i = (next() % m.len() as u64) as usize;
                    m[i] = next() as u8;
                }
            }
            // Truncate.
            1 => m.truncate((next() % m.len() as u64) as usize),
            // Change one digit of the JSON (offsets, counts, indices).
            _ => {
                let digits: Vec<usize> = (20..m.len().min(900))
                    .filter(|&i| m[i].is_ascii_digit())
                    .collect();
                let i = digits[(next() % digits.len() as u64) as usize];
                m[i] = b'0' + (next() % 10) as u8;
            }
        }
        std::fs::write(&path, &m).unwrap();
        let loaded = std::panic::catch_unwind(|| resolve_scene(path.to_str().unwrap()));
        match loaded {
            Ok(Ok(_)) => ok += 1,
            Ok(Err(e)) => {
                assert!(e.to_string().contains("m.glb"), "{e}");
                errors += 1;
            }
            Err(_) => panic!("round {round}: loading a mutated .glb panicked"),
        }
    }
    assert!(errors > 100, "{ok} loaded, {errors} errors");
}

#[test]
#[ignore = "needs ../shared"]
fn shared_bunny_converts_to_glb_with_the_same_triangles() {
    let obj = repo("../shared/scenes/bunny.obj");
    assert!(obj.exists(), "../shared not found");
    let dir = temp_dir("bunny_glb");
    let glb = dir.join("bunny.glb");
    let status = std::process::Command::new("python3")
        .arg(repo("host/scripts/obj_to_glb.py"))
        .arg(&obj)
        .arg("--camera")
        .arg(repo("../shared/scenes/bunny.camera"))
        .arg("--out")
        .arg(&glb)
        .status()
        .expect("run python3");
    assert!(status.success());
    let mesh = load_obj(&obj).unwrap();
    let spec = resolve_scene(glb.to_str().unwrap()).unwrap();
    let expected: Vec<_> = (0..mesh.triangle_count())
        .map(|t| mesh.triangle_f32(t))
        .collect();
    assert_eq!(spec.triangles.len(), expected.len());
    // The script parses decimals to f64 and rounds to f32, the reader parses to f32 directly:
    // equal but for rare double roundings (one unit in the last place at most).
    let far = spec
        .triangles
        .iter()
        .flatten()
        .flatten()
        .zip(expected.iter().flatten().flatten())
        .filter(|(a, b)| (*a - *b).abs() > f32::EPSILON * b.abs().max(f32::MIN_POSITIVE))
        .count();
    assert_eq!(far, 0);
    let out = dir.join("bunny.png");
    render(&[
        glb.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--width",
        "64",
        "--spp",
        "1",
    ])
    .unwrap();
    assert!(read_png(&out).2.iter().any(|&b| b > 0));
}

// --- OpenEXR ---------------------------------------------------------------------------------

/// A PFM file's linear pixels, rows top to bottom (PFM stores them bottom to top).
fn read_pfm(path: &Path) -> (u32, u32, Vec<[f32; 3]>) {
    let bytes = std::fs::read(path).unwrap();
    let text = String::from_utf8_lossy(&bytes[..bytes.len().min(64)]).into_owned();
    let mut lines = text.splitn(4, '\n');
    assert_eq!(lines.next(), Some("PF"));
    let size: Vec<u32> = lines
        .next()
        .unwrap()
        .split(' ')
        .map(|x| x.parse().unwrap())
        .collect();
    assert_eq!(lines.next(), Some("-1.0"));
    // The pixels are the file's last width × height × 12 bytes.
    let start = bytes.len() - (size[0] * size[1] * 12) as usize;
    let floats: Vec<f32> = bytes[start..]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let rows: Vec<Vec<[f32; 3]>> = floats
        .chunks_exact(3 * size[0] as usize)
        .map(|r| r.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect())
        .collect();
    (size[0], size[1], rows.into_iter().rev().flatten().collect())
}

#[test]
fn exr_holds_the_pfm_values_bit_for_bit() {
    let dir = temp_dir("exr");
    let (png, pfm, exr) = (dir.join("c.png"), dir.join("c.pfm"), dir.join("c.exr"));
    render(&[
        "cornell",
        "--out",
        png.to_str().unwrap(),
        "--linear",
        pfm.to_str().unwrap(),
        "--exr",
        exr.to_str().unwrap(),
        "--width",
        "40",
        "--height",
        "30",
        "--spp",
        "4",
    ])
    .unwrap();
    let (w, h, linear) = read_pfm(&pfm);
    let frame = host::exr::read_exr(&exr).unwrap();
    assert_eq!((frame.width, frame.height), (w, h));
    let bits = |v: &[[f32; 3]]| -> Vec<u32> { v.iter().flatten().map(|x| x.to_bits()).collect() };
    assert_eq!(bits(&frame.linear), bits(&linear));
    // Not a trivial image: some light and some above 1 (unclipped).
    assert!(linear.iter().flatten().any(|&x| x > 1.0));
}

#[test]
#[ignore = "needs python3 with the OpenEXR bindings (pip install openexr)"]
fn exr_reads_back_in_python_openexr_with_the_pfm_values() {
    let dir = temp_dir("exr_python");
    let (png, pfm, exr) = (dir.join("c.png"), dir.join("c.pfm"), dir.join("c.exr"));
    render(&[
        "spheres",
        "--out",
        png.to_str().unwrap(),
        "--linear",
        pfm.to_str().unwrap(),
        "--exr",
        exr.to_str().unwrap(),
        "--width",
        "40",
        "--spp",
        "4",
    ])
    .unwrap();
    let out = std::process::Command::new("python3")
        .arg(repo("host/scripts/check_exr.py"))
        .arg(&exr)
        .arg(&pfm)
        .output()
        .expect("run python3");
    let text =
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{text}");
    assert!(text.contains("same linear values"), "{text}");
}
