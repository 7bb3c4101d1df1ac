//! A structure-aware mutation run over scene files: many mutated copies of every built-in
//! scene's dump (fields deleted, values of the wrong type, huge and special numbers, deep
//! nesting, long and binary strings, lists grown past their bounds, special files as mesh
//! paths, truncated and byte-flipped text) go through everything `raykernel render` does
//! before and during a render: load, the request checks (bounds, camera, memory), the plan,
//! and a tiny render in both modes. None may panic, and none may take long: bad input gets a
//! typed error, within the stated bounds.
//!
//! `RAYKERNEL_MUTATIONS` sets the copies per scene (default 50; CI runs more under an
//! address-space limit, see `.ci/run`). Each case prints nothing unless it fails, when the
//! seed and the mutated text (shortened) are in the message.

mod common;

use common::{temp_dir, Rng};
use host::render::{render, RenderOptions};
use host::scenefile::{dump, parse_scene_file};
use host::trace::Mode;
use raykernel::render::scenes;
use serde_json::{Map, Value};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Longest a case may take before it counts as a time-out.
const CASE_LIMIT: Duration = Duration::from_secs(20);

/// Special paths a mutated `mesh` may name.
fn special_paths(dir: &Path) -> Vec<String> {
    let mut paths = vec![
        "/dev/zero".to_string(),
        "/dev/null".to_string(),
        "/dev/urandom".to_string(),
        "/proc/self/status".to_string(),
        dir.display().to_string(),
        dir.join("missing.obj").display().to_string(),
        dir.join("binary.obj").display().to_string(),
        dir.join("ok.obj").display().to_string(),
        String::new(),
    ];
    let fifo = dir.join("pipe.obj");
    let made = fifo.exists()
        || std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .is_ok_and(|s| s.success());
    if made {
        paths.push(fifo.display().to_string());
    } else {
        println!("skipped: named pipe as a mesh path (mkfifo unavailable)");
    }
    paths
}

/// Every value's location in `v`, as a path of keys and indices.
fn locations(v: &Value, here: &mut Vec<Step>, out: &mut Vec<Vec<Step>>) {
    out.push(here.clone());
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                here.push(Step::Key(k.clone()));
                locations(x, here, out);
                here.pop();
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                here.push(Step::Index(i));
                locations(x, here, out);
                here.pop();
            }
        }
        _ => {}
    }
}

#[derive(Clone, Debug)]
enum Step {
    Key(String),
    Index(usize),
}

fn at<'v>(v: &'v mut Value, path: &[Step]) -> Option<&'v mut Value> {
    let mut cur = v;
    for s in path {
        cur = match (s, cur) {
            (Step::Key(k), Value::Object(m)) => m.get_mut(k)?,
            (Step::Index(i), Value::Array(a)) => a.get_mut(*i)?,
            _ => return None,
        };
    }
    Some(cur)
}

const NUMBERS: [f64; 16] = [
    0.0,
    -0.0,
    -1.0,
    1e39,
    -1e39,
    1e20,
    -1e20,
    4294967295.0,
    4294967296.0,
    8191.9,
    8192.5,
    -8193.0,
    1e-45,
    3.4e38,
    16384.0,
    100000.0,
];

fn number(x: f64) -> Value {
    serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)
}

/// One structure-aware mutation of `v`.
fn mutate(v: &mut Value, rng: &mut Rng, specials: &[String]) {
    let mut locs = Vec::new();
    locations(v, &mut Vec::new(), &mut locs);
    let path = locs[rng.below(locs.len())].clone();
    match rng.below(11) {
        // Delete a field or an entry.
        0 => {
            if let Some((last, parent)) = path.split_last() {
                match (last, at(v, parent)) {
                    (Step::Key(k), Some(Value::Object(m))) => {
                        m.remove(k);
                    }
                    (Step::Index(i), Some(Value::Array(a))) => {
                        a.remove(*i);
                    }
                    _ => {}
                }
            }
        }
        // A value of another type.
        1 => {
            let other = match rng.below(6) {
                0 => Value::Null,
                1 => Value::Bool(true),
                2 => Value::String("x".into()),
                3 => Value::Array(vec![number(1.0)]),
                4 => Value::Object(Map::new()),
                _ => number(7.0),
            };
            if let Some(x) = at(v, &path) {
                *x = other;
            }
        }
        // A huge, tiny or boundary number where a number was.
        2 | 3 => {
            if let Some(x) = at(v, &path) {
                if x.is_number() || rng.below(4) == 0 {
                    *x = number(NUMBERS[rng.below(NUMBERS.len())]);
                }
            }
        }
        // Deep nesting.
        4 => {
            let depth = [10, 127, 129, 5000][rng.below(4)];
            if let Some(x) = at(v, &path) {
                let mut nested = x.take();
                for _ in 0..depth {
                    nested = Value::Array(vec![nested]);
                }
                *x = nested;
            }
        }
        // A long or binary string (as a value or as a key).
        5 => {
            let s = if rng.below(2) == 0 {
                "y".repeat(1 << 20)
            } else {
                "\u{1b}[2J\u{0}\u{7}\u{feff}name".to_string()
            };
            match at(v, &path) {
                Some(Value::Object(m)) if rng.below(2) == 0 => {
                    m.insert(s, number(1.0));
                }
                Some(x) => *x = Value::String(s),
                None => {}
            }
        }
        // Grow a list past its bounds (lights) or by many entries (materials, objects).
        6 => {
            let key = ["lights", "materials", "objects"][rng.below(3)];
            let n = [9, 100, 1000][rng.below(3)];
            if let Some(Value::Array(a)) = v.get_mut(key) {
                if let Some(first) = a.first().cloned() {
                    a.extend(std::iter::repeat_n(first, n));
                }
            }
        }
        // A special file as a mesh path.
        7 => {
            if let Some(Value::Array(objects)) = v.get_mut("objects") {
                if !objects.is_empty() {
                    let i = rng.below(objects.len());
                    if let Value::Object(o) = &mut objects[i] {
                        o.remove("triangles");
                        o.remove("spheres");
                        let p = specials[rng.below(specials.len())].clone();
                        o.insert("mesh".into(), Value::String(p));
                    }
                }
            }
        }
        // Settings beyond their bounds.
        8 => {
            let key = ["width", "height", "spp", "max_depth"][rng.below(4)];
            let x = [0.0, 1.0, 16385.0, 65537.0, 4294967295.0, 100000.0][rng.below(6)];
            if let Some(Value::Object(s)) = v.get_mut("settings") {
                s.insert(key.into(), number(x));
            }
        }
        // An unknown field.
        9 => {
            if let Some(Value::Object(m)) = at(v, &path) {
                m.insert("unknown_field".into(), Value::Bool(false));
            }
        }
        // The camera pointed at itself or far away.
        _ => {
            if let Some(Value::Object(c)) = v.get_mut("camera") {
                let eye = c.get("eye").cloned().unwrap_or(Value::Null);
                match rng.below(3) {
                    0 => {
                        c.insert("look_at".into(), eye);
                    }
                    1 => {
                        let far = Value::Array(vec![number(1e20), number(0.0), number(0.0)]);
                        c.insert("eye".into(), far);
                    }
                    _ => {
                        c.insert("vfov_deg".into(), number([0.0, 180.0, 1e-30][rng.below(3)]));
                    }
                }
            }
        }
    }
}

/// The text of a mutated value, sometimes damaged as bytes too.
fn text_of(v: &Value, rng: &mut Rng) -> String {
    let mut text = serde_json::to_string_pretty(v).unwrap_or_default();
    match rng.below(8) {
        0 => {
            let cut = rng.below(text.len() + 1);
            text = text.chars().take(cut).collect();
        }
        1 => {
            let mut bytes = text.into_bytes();
            if !bytes.is_empty() {
                let i = rng.below(bytes.len());
                bytes[i] ^= 1 << rng.below(8);
            }
            text = String::from_utf8_lossy(&bytes).into_owned();
        }
        2 => text.insert(0, '\u{feff}'),
        _ => {}
    }
    text
}

/// Load, check, plan and render (tiny) one scene-file text; the error, if any, as text.
fn run_case(text: &str, path: &Path) -> Result<(), String> {
    let mut spec = parse_scene_file(text, path).map_err(|e| e.to_string())?;
    for mode in [Mode::F32, Mode::Fixed] {
        host::cli::check_render_request(&spec, mode, true).map_err(|e| e.to_string())?;
    }
    spec.settings.width = spec.settings.width.min(6);
    spec.settings.height = spec.settings.height.min(5);
    spec.settings.spp = spec.settings.spp.min(2);
    for mode in [Mode::F32, Mode::Fixed] {
        let options = RenderOptions {
            mode,
            threads: 1,
            ..RenderOptions::default()
        };
        render(&spec.data(), spec.settings, &options).map_err(|e| format!("{e:?}"))?;
    }
    Ok(())
}

fn short(text: &str) -> String {
    host::error::for_terminal(&text.chars().take(2000).collect::<String>())
}

#[test]
fn mutated_scene_files_never_panic_abort_or_hang() {
    let per_scene: usize = std::env::var("RAYKERNEL_MUTATIONS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(50);
    let dir = temp_dir("scene_mutation");
    std::fs::write(
        dir.join("binary.obj"),
        b"\xef\xbb\xbfv 1 2\x00\x1b[2J\nf 1 2 3\n",
    )
    .unwrap();
    std::fs::write(dir.join("ok.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let specials = special_paths(&dir);
    let path: PathBuf = dir.join("mutated.json");
    let (mut cases, mut loaded, mut slowest) = (0usize, 0usize, Duration::ZERO);
    let start = Instant::now();
    for (k, scene) in scenes::ALL.iter().enumerate() {
        let base: Value = serde_json::from_str(&dump(scene, &[])).unwrap();
        for n in 0..per_scene {
            let seed = (k as u64) << 32 | n as u64;
            let mut rng = Rng::new(seed);
            let mut v = base.clone();
            for _ in 0..=rng.below(3) {
                mutate(&mut v, &mut rng, &specials);
            }
            let text = text_of(&v, &mut rng);
            let t = Instant::now();
            let outcome = std::panic::catch_unwind(|| run_case(&text, &path));
            let took = t.elapsed();
            match outcome {
                Err(_) => panic!(
                    "panic on {} mutation seed {seed:#x}: {}",
                    scene.name,
                    short(&text)
                ),
                Ok(Ok(())) => loaded += 1,
                Ok(Err(msg)) => {
                    assert!(!msg.is_empty(), "empty message for seed {seed:#x}");
                    // Messages quote inputs only within bounds once made terminal-safe.
                    assert!(
                        host::error::for_terminal(&msg).len() < 4000,
                        "seed {seed:#x}: message too long"
                    );
                }
            }
            assert!(
                took < CASE_LIMIT,
                "time-out: {} mutation seed {seed:#x} took {took:?}: {}",
                scene.name,
                short(&text)
            );
            slowest = slowest.max(took);
            cases += 1;
        }
    }
    println!(
        "mutation run: {cases} cases ({} scenes × {per_scene}), {loaded} rendered, {} \
         rejected with a message, 0 panics, slowest case {slowest:?}, {:?} in all",
        scenes::ALL.len(),
        cases - loaded,
        start.elapsed()
    );
    assert_eq!(cases, scenes::ALL.len() * per_scene);
}
