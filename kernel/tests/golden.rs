//! Golden hashes shared with the on-target tests (`tests/qemu`): computes every case of
//! `raykernel_testkit::golden` on the host and compares with `tests/golden/kernel_hashes.txt`, the
//! one file both sides read. `BLESS=1 cargo test -p raykernel --test golden` rewrites it.

use raykernel_testkit::golden as cases;

use std::path::PathBuf;

fn golden_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/golden/kernel_hashes.txt")
}

fn render(values: &[(&str, u64)]) -> String {
    let mut s = String::from(
        "# FNV-1a hashes of kernel results on the cases of raykernel_testkit::golden, read by the\n\
         # host test kernel/tests/golden.rs and by the on-target tests (tests/qemu/build.rs).\n\
         # Rewrite with: BLESS=1 cargo test -p raykernel --test golden\n",
    );
    for (name, v) in values {
        s.push_str(&format!("{name} = {v:#018x}\n"));
    }
    s
}

#[test]
fn golden_hashes_match_file() {
    // `None`: a case this build cannot compute (a kernel feature it leaves out).
    let computed: Vec<(&str, Option<u64>)> = cases::NAMES
        .iter()
        .map(|&name| match cases::compute_any(name) {
            Ok(v) => (name, Some(v)),
            Err(cases::Fail::NotLinked) => {
                eprintln!("skipped golden case {name}: needs `--features path-tracing`");
                (name, None)
            }
            Err(e) => panic!("case {name}: {e:?}"),
        })
        .collect();
    let path = golden_path();
    if std::env::var_os("BLESS").is_some_and(|v| v == "1") {
        let computed: Vec<(&str, u64)> = computed
            .iter()
            .map(|&(name, v)| {
                let v = v.unwrap_or_else(|| panic!("cannot bless without case {name}"));
                (name, v)
            })
            .collect();
        std::fs::write(&path, render(&computed)).expect("write golden file");
        eprintln!("blessed {}", path.display());
        return;
    }
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e} (run with BLESS=1 to create it)", path.display()));
    let mut file = Vec::new();
    cases::parse_golden(&text, |name, v| file.push((name.to_string(), v)))
        .unwrap_or_else(|line| panic!("{}:{line}: malformed line", path.display()));
    let file_names: Vec<&str> = file.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        file_names,
        cases::NAMES,
        "case list and {} differ (BLESS=1 rewrites the file)",
        path.display()
    );
    let mut bad = Vec::new();
    for ((name, want), (_, got)) in file.iter().zip(&computed) {
        let Some(got) = got else { continue };
        if want != got {
            bad.push(format!("{name}: file {want:#018x}, computed {got:#018x}"));
        }
    }
    assert!(
        bad.is_empty(),
        "golden hashes differ (BLESS=1 rewrites the file if the change is intended):\n{}",
        bad.join("\n")
    );
}

#[test]
fn golden_parser_rejects_malformed_lines() {
    assert_eq!(cases::parse_golden("a = 0x1\nb 0x2\n", |_, _| {}), Err(2));
    assert_eq!(cases::parse_golden("a = 12\n", |_, _| {}), Err(1));
    let mut seen = Vec::new();
    cases::parse_golden("# c\n\n x = 0x00ff # tail\n", |n, v| {
        seen.push((n.to_string(), v))
    })
    .unwrap();
    assert_eq!(seen, [("x".to_string(), 0xff)]);
}

#[test]
fn icosphere_is_closed_and_rays_are_valid() {
    // Every edge of the generated mesh is shared by exactly two triangles (bit-equal vertices).
    let tris: Vec<_> = (0..cases::ICO_TRIS).map(cases::ico_triangle).collect();
    let mut edges = std::collections::HashMap::new();
    for t in &tris {
        for k in 0..3 {
            let (a, b) = (t[k].map(f32::to_bits), t[(k + 1) % 3].map(f32::to_bits));
            *edges
                .entry(if a < b { (a, b) } else { (b, a) })
                .or_insert(0) += 1;
        }
    }
    assert_eq!(edges.len(), 120);
    assert!(edges.values().all(|&c| c == 2));
    // The ray set exercises hits and misses.
    use raykernel::Accel;
    let mut mesh = cases::empty_mesh::<f32>();
    cases::icosphere(&mut mesh).unwrap();
    let linear = raykernel::Linear::new(&mesh);
    let mut hits = 0;
    for i in 0..cases::RAY_COUNT {
        let r = cases::ray::<f32>(i).unwrap();
        cases::ray::<raykernel::I16F16>(i).unwrap();
        hits += usize::from(linear.intersect(&r).is_some());
    }
    assert!(
        (cases::RAY_COUNT / 2..cases::RAY_COUNT).contains(&hits),
        "{hits} of {} rays hit",
        cases::RAY_COUNT
    );
}
