//! `host check`: every way of rendering a scene must give the same bytes.
//!
//! For each scene and mode, the reference is the kernel's single-threaded whole-image path
//! ([`raykernel::render::Renderer::render_srgb8`], default BVH). Compared with it, byte for byte:
//! the host's parallel tiles at 1, 2 and 3 threads and with an odd tile size, and every
//! accelerator (brute force; the BVH and the 4-wide BVH with each builder at leaf sizes 1 and
//! 4; the uniform grid; the kd-tree).

use crate::error::Error;
use crate::render::{mode_name, render, render_reference, Image, RenderError, RenderOptions};
use crate::spec::SceneSpec;
use crate::trace::Mode;
use raykernel::bvh::{BuildOptions, BuilderKind};
use raykernel::AccelKind;
use serde::Serialize;

/// The first pixel where two images differ.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct PixelDiff {
    /// Column.
    pub x: u32,
    /// Row (0 is the top).
    pub y: u32,
    /// The reference's RGB there.
    pub expected: [u8; 3],
    /// The other image's RGB there.
    pub actual: [u8; 3],
    /// Pixels that differ in all.
    pub count: usize,
}

/// Compares two images of the same size; `None` if they are byte-identical.
///
/// # Panics
/// If the sizes differ.
#[must_use]
pub fn first_difference(expected: &Image, actual: &Image) -> Option<PixelDiff> {
    assert_eq!(
        (expected.width, expected.height, expected.rgb.len()),
        (actual.width, actual.height, actual.rgb.len()),
        "images of different sizes"
    );
    let w = expected.width.max(1) as usize;
    let mut first = None;
    let mut count = 0;
    for (i, (a, b)) in expected
        .rgb
        .chunks_exact(3)
        .zip(actual.rgb.chunks_exact(3))
        .enumerate()
    {
        if a != b {
            count += 1;
            if first.is_none() {
                first = Some((i, [a[0], a[1], a[2]], [b[0], b[1], b[2]]));
            }
        }
    }
    first.map(|(i, expected, actual)| PixelDiff {
        x: (i % w) as u32,
        y: (i / w) as u32,
        expected,
        actual,
        count,
    })
}

/// One way of rendering that must match the reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Variant {
    /// Threads.
    pub threads: usize,
    /// Tile size.
    pub tile: (u32, u32),
    /// Accelerator.
    pub accel: AccelKind,
}

impl Variant {
    /// A short description: `2 threads, 16x16 tiles, bvh sah leaf 4`.
    #[must_use]
    pub fn describe(&self) -> String {
        format!(
            "host tiles ({} thread{}, {}x{} tiles, {})",
            self.threads,
            if self.threads == 1 { "" } else { "s" },
            self.tile.0,
            self.tile.1,
            self.accel
        )
    }
}

/// Every variant `host check` renders: thread counts and tile sizes with the default BVH, then
/// every accelerator kind (for the BVH: each builder, leaves of 1 and 4) at 2 threads.
#[must_use]
pub fn variants() -> Vec<Variant> {
    let bvh = AccelKind::default();
    let mut v: Vec<Variant> = [(1, (16, 16)), (2, (16, 16)), (3, (16, 16)), (2, (7, 5))]
        .into_iter()
        .map(|(threads, tile)| Variant {
            threads,
            tile,
            accel: bvh,
        })
        .collect();
    // Every structure; the BVHs with each builder and leaves of 1 and 4.
    for kind in AccelKind::ALL {
        let kinds: Vec<AccelKind> = if kind.build_options().is_some() {
            BuilderKind::ALL
                .into_iter()
                .flat_map(|builder| {
                    [1, 4].map(|max_leaf_size| {
                        kind.with_build_options(BuildOptions {
                            builder,
                            max_leaf_size,
                            reinsertion: true,
                        })
                    })
                })
                .collect()
        } else {
            vec![kind]
        };
        for accel in kinds {
            v.push(Variant {
                threads: 2,
                tile: (16, 16),
                accel,
            });
        }
    }
    v
}

/// The outcome for one scene in one mode.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CaseReport {
    /// Scene name.
    pub scene: String,
    /// `f32` or `fixed`.
    pub mode: &'static str,
    /// Image size.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Renders compared with the reference.
    pub compared: usize,
    /// Each variant that differs, with its first differing pixel.
    pub differences: Vec<(String, PixelDiff)>,
}

/// Renders per scene and mode: the reference and every [`variants`] entry.
#[must_use]
pub fn renders_per_case() -> usize {
    variants().len() + 1
}

/// Renders `spec` (at its own settings) in `mode` every way and compares each with the
/// kernel's single-threaded whole-image render.
///
/// # Errors
/// A scene the kernel rejects (as [`SceneSpec::explain`]) or a thread pool that cannot start.
/// Differences are not errors: they are in the report.
pub fn check_scene(spec: &SceneSpec, mode: Mode) -> Result<CaseReport, Error> {
    check_scene_with(spec, mode, &mut || ())
}

/// As [`check_scene`], calling `rendered` after each of the [`renders_per_case`] renders
/// (for progress).
///
/// # Errors
/// As [`check_scene`].
pub fn check_scene_with(
    spec: &SceneSpec,
    mode: Mode,
    rendered: &mut dyn FnMut(),
) -> Result<CaseReport, Error> {
    let data = spec.data();
    let settings = spec.settings;
    let name = mode_name(mode);
    let reference = render_reference(&data, settings, mode, AccelKind::default())
        .map_err(|e| spec.explain(&e, name))?;
    rendered();
    let mut report = CaseReport {
        scene: spec.name.clone(),
        mode: name,
        width: settings.width,
        height: settings.height,
        compared: 0,
        differences: Vec::new(),
    };
    for v in variants() {
        let options = RenderOptions {
            mode,
            accel: v.accel,
            threads: v.threads,
            tile: v.tile,
            progress: false,
        };
        let image = render(&data, settings, &options)
            .map_err(|e| match e {
                RenderError::Scene(e) => spec.explain(&e, name),
                RenderError::Pool(msg) => Error::Usage(format!("cannot start threads: {msg}")),
            })?
            .frame
            .srgb8();
        rendered();
        report.compared += 1;
        if let Some(d) = first_difference(&reference, &image) {
            report.differences.push((v.describe(), d));
        }
    }
    Ok(report)
}

/// One line per difference: scene, mode, variant, first pixel and both values.
#[must_use]
pub fn describe_differences(reports: &[CaseReport]) -> Vec<String> {
    reports
        .iter()
        .flat_map(|r| {
            r.differences.iter().map(move |(variant, d)| {
                format!(
                    "{} ({}): {variant} differs from the kernel's render_srgb8: first at pixel \
                     ({}, {}): expected {:?}, got {:?} ({} {})",
                    r.scene,
                    r.mode,
                    d.x,
                    d.y,
                    d.expected,
                    d.actual,
                    d.count,
                    if d.count == 1 {
                        "pixel differs"
                    } else {
                        "pixels differ"
                    }
                )
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_difference_names_the_pixel() {
        let a = Image {
            width: 3,
            height: 2,
            rgb: (0..18).collect(),
        };
        assert_eq!(first_difference(&a, &a), None);
        let mut b = a.clone();
        b.rgb[13] ^= 1; // pixel 4: (1, 1), green
        b.rgb[17] ^= 0x80; // pixel 5: (2, 1)
        let d = first_difference(&a, &b).unwrap();
        assert_eq!((d.x, d.y, d.count), (1, 1, 2));
        assert_eq!((d.expected, d.actual), ([12, 13, 14], [12, 12, 14]));
    }

    #[test]
    fn variants_cover_threads_tiles_and_every_accelerator() {
        let v = variants();
        assert!(v.iter().any(|x| x.accel == AccelKind::Linear));
        assert_eq!(
            v.iter()
                .filter(|x| matches!(x.accel, AccelKind::Bvh(_)))
                .count(),
            4 + 6
        );
        assert_eq!(
            v.iter()
                .filter(|x| matches!(x.accel, AccelKind::Bvh4(_)))
                .count(),
            6
        );
        assert_eq!(
            v.iter()
                .filter(|x| matches!(x.accel, AccelKind::Bvh8(_)))
                .count(),
            6
        );
        assert!(v.iter().any(|x| x.threads == 3));
        assert!(v.iter().any(|x| x.tile == (7, 5)));
    }
}
