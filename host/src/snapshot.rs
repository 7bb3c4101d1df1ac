//! Snapshot comparisons: rendered images against committed goldens, exactly.
//!
//! Two goldens per render: its FNV-1a-64 hash (over the 8-bit sRGB bytes, row-major, as
//! `testkit/src/golden.rs` hashes the kernel's renders) in the one hash file
//! `tests/golden/kernel_hashes.txt`, shared with the kernel's and the on-target tests; and a
//! small PNG in `tests/golden/images/`, so a failure can show what changed. A mismatch writes
//! `NAME.actual.png` and `NAME.diff.png` (differing pixels red over a dimmed copy of the
//! golden) and names them.

use crate::check::first_difference;
use crate::render::{decode_png, encode_png, Image};
use std::path::{Path, PathBuf};

/// 64-bit FNV-1a over a byte stream. The same value as `cases.rs`'s `Fnv::u32` fed the bytes
/// as little-endian 4-byte words, when the length is a multiple of 4 (as for every golden
/// render: 3 bytes per pixel, an even pixel count that is a multiple of 4).
#[must_use]
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// The name of a render's PNG, `<scene>_<mode>`; its line in the hash file is
/// `render_<scene>_<mode>` (read with `cases.rs`'s `parse_golden`, the one parser of that file).
#[must_use]
pub fn snapshot_name(scene: &str, mode: &str) -> String {
    format!("{scene}_{mode}")
}

/// A golden image that does not match.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Mismatch {
    /// What differs.
    pub message: String,
    /// The actual image, written for inspection.
    pub actual: PathBuf,
    /// The diff image (absent when the sizes differ or the golden is unreadable).
    pub diff: Option<PathBuf>,
}

/// An image of `expected`'s size: pixels that differ in `actual` are pure red, the others a
/// dimmed grey copy of `expected`.
///
/// # Panics
/// If the sizes differ.
#[must_use]
pub fn diff_image(expected: &Image, actual: &Image) -> Image {
    assert_eq!(
        expected.rgb.len(),
        actual.rgb.len(),
        "images of different sizes"
    );
    let rgb = expected
        .rgb
        .chunks_exact(3)
        .zip(actual.rgb.chunks_exact(3))
        .flat_map(|(a, b)| {
            if a == b {
                let luma = (u16::from(a[0]) + u16::from(a[1]) + u16::from(a[2])) / 12;
                [luma as u8; 3]
            } else {
                [255, 0, 0]
            }
        })
        .collect();
    Image {
        width: expected.width,
        height: expected.height,
        rgb,
    }
}

/// Compares `actual` with the golden PNG `golden`, exactly. On a mismatch, writes
/// `out_dir/NAME.actual.png` and (same size) `out_dir/NAME.diff.png`.
///
/// # Errors
/// A [`Mismatch`] naming the first differing pixel and the files written.
pub fn compare_with_png(
    name: &str,
    actual: &Image,
    golden: &Path,
    out_dir: &Path,
) -> Result<(), Mismatch> {
    let expected = std::fs::read(golden)
        .map_err(|e| e.to_string())
        .and_then(|b| decode_png(&b));
    let problem = match &expected {
        Err(e) => format!("{}: cannot read the golden: {e}", golden.display()),
        Ok(exp) if (exp.width, exp.height) != (actual.width, actual.height) => format!(
            "{}: golden is {}x{}, render is {}x{}",
            golden.display(),
            exp.width,
            exp.height,
            actual.width,
            actual.height
        ),
        Ok(exp) => match first_difference(exp, actual) {
            None => return Ok(()),
            Some(d) => format!(
                "{}: {} {}, first at ({}, {}): golden {:?}, render {:?}",
                golden.display(),
                d.count,
                if d.count == 1 {
                    "pixel differs"
                } else {
                    "pixels differ"
                },
                d.x,
                d.y,
                d.expected,
                d.actual
            ),
        },
    };
    let _ = std::fs::create_dir_all(out_dir);
    let actual_path = out_dir.join(format!("{name}.actual.png"));
    let write = |path: &Path, image: &Image| {
        encode_png(image).and_then(|b| std::fs::write(path, b).map_err(|e| e.to_string()))
    };
    let mut message = problem;
    if let Err(e) = write(&actual_path, actual) {
        message.push_str(&format!(
            " (could not write {}: {e})",
            actual_path.display()
        ));
    }
    let diff = match &expected {
        Ok(exp) if exp.rgb.len() == actual.rgb.len() => {
            let p = out_dir.join(format!("{name}.diff.png"));
            write(&p, &diff_image(exp, actual)).ok().map(|()| p)
        }
        _ => None,
    };
    Err(Mismatch {
        message,
        actual: actual_path,
        diff,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv_known_values() {
        // Published FNV-1a 64 test vectors.
        assert_eq!(fnv1a64(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a64(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a64(b"foobar"), 0x8594_4171_f739_67e8);
    }
}
