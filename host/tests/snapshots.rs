//! Snapshot tests: each built-in scene in each mode, rendered through the host's parallel tiles
//! at the scene's own (small) settings, must match **exactly**
//! - the `render_<scene>_<mode>` line of `tests/golden/kernel_hashes.txt` (FNV-1a-64 of the
//!   sRGB bytes, the hash file the kernel's golden test and the on-target tests check), and
//! - the PNG `tests/golden/images/<scene>_<mode>.png`.
//!
//! A mismatch writes `target/snapshots/<name>.actual.png` and `<name>.diff.png` and names them.
//! `cargo xtask bless` (or `BLESS=1 cargo test -p raykernel-host --test snapshots`) rewrites the
//! PNGs; the hash lines are the kernel's (`BLESS=1 cargo test -p raykernel --test golden`).

mod common;

use raykernel_testkit::golden as cases;

use host::render::{decode_png, encode_png, mode_name, render, Image, RenderOptions};
use host::snapshot::{compare_with_png, diff_image, fnv1a64, snapshot_name};
use host::trace::Mode;
use raykernel::render::scenes;
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// `target/snapshots`, beside the integration tests' temp dir.
fn out_dir() -> PathBuf {
    let tmp = Path::new(env!("CARGO_TARGET_TMPDIR"));
    tmp.parent().unwrap_or(tmp).join("snapshots")
}

fn blessing() -> bool {
    std::env::var_os("BLESS").is_some_and(|v| v == "1")
}

/// The render the goldens hold: the host's tiles (2 threads) at the scene's own settings.
fn snapshot(d: &scenes::SceneData<'_>, mode: Mode) -> Image {
    let options = RenderOptions {
        mode,
        threads: 2,
        ..RenderOptions::default()
    };
    render(d, d.settings, &options).unwrap().frame.srgb8()
}

#[test]
fn every_built_in_scene_matches_its_golden_hash_and_image_in_both_modes() {
    let hash_file = repo().join("tests/golden/kernel_hashes.txt");
    let text = std::fs::read_to_string(&hash_file)
        .unwrap_or_else(|e| panic!("{}: {e}", hash_file.display()));
    let mut hashes = Vec::new();
    cases::parse_golden(&text, |name, v| hashes.push((name.to_string(), v)))
        .unwrap_or_else(|line| panic!("{}:{line}: malformed line", hash_file.display()));
    // Until the kernel's render cases land in the hash file, only the PNGs can be checked;
    // once any `render_` line is there, every one must be.
    let kernel_has_renders = hashes.iter().any(|(n, _)| n.starts_with("render_"));
    if !kernel_has_renders {
        eprintln!(
            "note: {} has no render_* lines yet (testkit/src/golden.rs has no render cases); \
             checking the PNGs only",
            hash_file.display()
        );
    }
    let mut failures = Vec::new();
    for d in scenes::ALL {
        for mode in [Mode::F32, Mode::Fixed] {
            let name = snapshot_name(d.name, mode_name(mode));
            let image = snapshot(&d, mode);
            let hash = fnv1a64(&image.rgb);
            let line = format!("render_{name}");
            match hashes.iter().find(|(n, _)| *n == line) {
                Some((_, want)) if *want == hash => {}
                Some((_, want)) => failures.push(format!(
                    "{}: {line} = {want:#018x}, but the host's render hashes to {hash:#018x}",
                    hash_file.display()
                )),
                None if kernel_has_renders => failures.push(format!(
                    "{}: no line `{line}`: add the case to testkit/src/golden.rs and run \
                     `cargo xtask bless`",
                    hash_file.display()
                )),
                None => {}
            }
            let png = repo().join(format!("tests/golden/images/{name}.png"));
            if blessing() {
                std::fs::create_dir_all(png.parent().unwrap()).unwrap();
                std::fs::write(&png, encode_png(&image).unwrap()).unwrap();
                eprintln!("blessed {} ({hash:#018x})", png.display());
                continue;
            }
            if let Err(m) = compare_with_png(&name, &image, &png, &out_dir()) {
                let diff = m
                    .diff
                    .map_or(String::new(), |p| format!(", diff in {}", p.display()));
                failures.push(format!(
                    "{} (actual in {}{diff}; `cargo xtask bless` rewrites the goldens if the \
                     change is intended)",
                    m.message,
                    m.actual.display()
                ));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "snapshots differ:\n{}",
        failures.join("\n")
    );
}

#[test]
fn a_one_bit_change_fails_and_writes_the_actual_and_diff_images() {
    let dir = common::temp_dir("snapshot_one_bit");
    let d = scenes::SPHERES;
    let image = snapshot(&d, Mode::F32);
    let golden = dir.join("golden.png");
    std::fs::write(&golden, encode_png(&image).unwrap()).unwrap();
    assert_eq!(compare_with_png("same", &image, &golden, &dir), Ok(()));

    let mut changed = image.clone();
    let (x, y) = (17, 11);
    changed.rgb[3 * (y * d.settings.width as usize + x)] ^= 1;
    assert_ne!(fnv1a64(&changed.rgb), fnv1a64(&image.rgb));
    let m = compare_with_png("flipped", &changed, &golden, &dir).unwrap_err();
    assert!(
        m.message.contains("1 pixel differs, first at (17, 11)"),
        "{}",
        m.message
    );
    assert_eq!(m.actual, dir.join("flipped.actual.png"));
    let actual = decode_png(&std::fs::read(&m.actual).unwrap()).unwrap();
    assert!(actual == changed);
    let diff_path = m.diff.unwrap();
    assert_eq!(diff_path, dir.join("flipped.diff.png"));
    let diff = decode_png(&std::fs::read(&diff_path).unwrap()).unwrap();
    assert!(diff == diff_image(&image, &changed));
    let red: Vec<usize> = diff
        .rgb
        .chunks(3)
        .enumerate()
        .filter(|(_, p)| *p == [255, 0, 0])
        .map(|(i, _)| i)
        .collect();
    assert_eq!(red, [y * d.settings.width as usize + x]);

    // A golden of another size fails too (no diff image then).
    let mut small = image.clone();
    small.height -= 1;
    small
        .rgb
        .truncate(3 * (small.width * small.height) as usize);
    let m = compare_with_png("size", &small, &golden, &dir).unwrap_err();
    assert!(
        m.message.contains("golden is 64x48, render is 64x47"),
        "{}",
        m.message
    );
    assert_eq!(m.diff, None);
}

#[test]
fn host_hash_is_the_golden_cases_fnv_over_little_endian_words() {
    for d in scenes::ALL {
        let image = snapshot(&d, Mode::F32);
        assert_eq!(image.rgb.len() % 4, 0, "{}", d.name);
        let mut h = cases::Fnv::new();
        for w in image.rgb.chunks_exact(4) {
            h.u32(u32::from_le_bytes([w[0], w[1], w[2], w[3]]));
        }
        assert_eq!(h.finish(), fnv1a64(&image.rgb), "{}", d.name);
    }
}
