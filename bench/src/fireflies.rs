//! Fireflies: isolated bright pixels of the default scene, above all around its glossy
//! highlight. The direct integrator reflects the small area light in the glossy sphere by
//! sampling the lobe alone, so the rim of the highlight gets rare, heavy samples; the path
//! integrator also samples the light there and weights both by MIS. Each integrator renders a
//! reference at 16× the samples, then several renders with other seeds; the section reports the
//! per-pixel error distribution pooled over those renders and counts isolated fireflies.

use crate::error::Error;
use crate::images::{render_f32, rmse};
use raykernel::glam::DVec3;
use raykernel::render::{encode_srgb8, scenes, Integrator, Material, SamplerKind, Settings};
use serde::Serialize;

/// A pixel counts as a firefly when it is at least this many times as bright as its reference
/// (linear luminance)…
pub const BRIGHTER: f64 = 2.0;
/// …its display value (8-bit sRGB of the luminance, scaled to [0, 1]) exceeds the reference's
/// by at least this much…
pub const VISIBLE: f64 = 0.05;
/// …and that excess is this many times the median absolute display error of its neighbours
/// (the eight around it, fewer at the border): isolated.
pub const ISOLATED: f64 = 5.0;

/// The per-pixel error distribution of one integrator over one region, pooled over its renders.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FireflyRow {
    /// `direct` or `path`.
    pub integrator: String,
    /// `whole image`, `glossy sphere` (the pixels whose centre sees it, its rim left out) or
    /// `glossy highlight` (the sphere's pixels near those that reflect the light).
    pub region: String,
    /// Image width and height.
    pub size: (u32, u32),
    /// Samples per pixel of each measured render.
    pub spp: u32,
    /// Measured renders (seeds 1, 2, …); the reference has seed 0.
    pub renders: u32,
    /// Samples per pixel of the reference (same integrator).
    pub reference_spp: u32,
    /// Pixels in the region (per render).
    pub pixels: usize,
    /// Median per-pixel error: RMS over the channels of the linear difference.
    pub median: f64,
    /// 99th percentile of the same.
    pub p99: f64,
    /// 99.9th percentile of the same.
    pub p999: f64,
    /// Largest of the same.
    pub max: f64,
    /// 99.9th percentile of the display error (8-bit sRGB of the luminance, scaled to [0, 1]).
    pub display_p999: f64,
    /// Isolated fireflies (see [`BRIGHTER`], [`VISIBLE`], [`ISOLATED`]) summed over the renders.
    pub fireflies: usize,
}

/// Image size, samples and renders for a full run or for `--quick`.
#[must_use]
pub fn workload(quick: bool) -> ((u32, u32), u32, u32) {
    if quick {
        ((32, 32), 8, 1)
    } else {
        ((64, 64), 256, 4)
    }
}

/// The default scene (`cornell`, Sobol samples, `f32`) with the direct integrator and with the
/// path integrator; references untimed on `threads` cores.
///
/// # Errors
/// A render the kernel refuses.
pub fn run(quick: bool, threads: usize) -> Result<Vec<FireflyRow>, Error> {
    let data = scenes::CORNELL;
    let (size, spp, renders) = workload(quick);
    let sphere = glossy_sphere_pixels(&data, size);
    let mut rows = Vec::new();
    for (name, integrator) in [
        ("direct", Integrator::Direct),
        (
            "path",
            Integrator::Path {
                max_length: host::scenefile::DEFAULT_MAX_PATH_LENGTH,
            },
        ),
    ] {
        eprintln!(
            "bench: fireflies: {name} {}x{}, {renders} × {spp} spp",
            size.0, size.1
        );
        let go = |spp, seed: u32| {
            let settings = Settings {
                width: size.0,
                height: size.1,
                spp,
                integrator,
                sampler: SamplerKind::Sobol,
                seed: data.settings.seed.wrapping_add(seed),
                ..data.settings
            };
            render_f32(&data, settings, threads).map(|r| r.frame.linear)
        };
        let reference = go(spp * 16, 0)?;
        let highlight = highlight_pixels(&sphere, &reference, size);
        let whole: Vec<usize> = (0..reference.len()).collect();
        let images = (1..=renders)
            .map(|seed| go(spp, seed))
            .collect::<Result<Vec<_>, _>>()?;
        let flags: Vec<Vec<bool>> = images
            .iter()
            .map(|im| isolated_fireflies(im, &reference, size))
            .collect();
        for (region, pixels) in [
            ("whole image", &whole),
            ("glossy sphere", &sphere),
            ("glossy highlight", &highlight),
        ] {
            if pixels.is_empty() {
                continue;
            }
            let mut linear = Vec::new();
            let mut shown = Vec::new();
            for im in &images {
                for &i in pixels.iter() {
                    linear.push(rmse(&[im[i]], &[reference[i]]));
                    shown.push((display(im[i]) - display(reference[i])).abs());
                }
            }
            linear.sort_by(f64::total_cmp);
            shown.sort_by(f64::total_cmp);
            rows.push(FireflyRow {
                integrator: name.into(),
                region: region.into(),
                size,
                spp,
                renders,
                reference_spp: spp * 16,
                pixels: pixels.len(),
                median: percentile(&linear, 0.5),
                p99: percentile(&linear, 0.99),
                p999: percentile(&linear, 0.999),
                max: percentile(&linear, 1.0),
                display_p999: percentile(&shown, 0.999),
                fireflies: flags
                    .iter()
                    .map(|f| pixels.iter().filter(|&&i| f[i]).count())
                    .sum(),
            });
        }
    }
    Ok(rows)
}

/// The value at quantile `q` of sorted, non-empty `v` (nearest rank).
fn percentile(v: &[f64], q: f64) -> f64 {
    v[((v.len() - 1) as f64 * q).round() as usize]
}

/// Linear luminance (Rec. 709 weights).
fn luminance(c: [f32; 3]) -> f64 {
    0.2126 * f64::from(c[0]) + 0.7152 * f64::from(c[1]) + 0.0722 * f64::from(c[2])
}

/// The luminance as an 8-bit image shows it, scaled to [0, 1].
fn display(c: [f32; 3]) -> f64 {
    f64::from(encode_srgb8(luminance(c) as f32)) / 255.0
}

/// Per pixel of `image` (row by row, `w`×`h`): whether it is an isolated firefly against
/// `reference`: at least [`BRIGHTER`] times as bright, brighter on display by at least
/// [`VISIBLE`], and by more than [`ISOLATED`] times its neighbours' median display error.
#[must_use]
pub fn isolated_fireflies(
    image: &[[f32; 3]],
    reference: &[[f32; 3]],
    (w, h): (u32, u32),
) -> Vec<bool> {
    let (w, h) = (w as usize, h as usize);
    let shown: Vec<f64> = image
        .iter()
        .zip(reference)
        .map(|(&p, &q)| display(p) - display(q))
        .collect();
    (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let excess = shown[i];
            if excess < VISIBLE || luminance(image[i]) < BRIGHTER * luminance(reference[i]) {
                return false;
            }
            let mut around: Vec<f64> = (y.saturating_sub(1)..(y + 2).min(h))
                .flat_map(|v| (x.saturating_sub(1)..(x + 2).min(w)).map(move |u| v * w + u))
                .filter(|&j| j != i)
                .map(|j| shown[j].abs())
                .collect();
            around.sort_by(f64::total_cmp);
            around
                .get(around.len() / 2)
                .is_none_or(|&m| excess > ISOLATED * m)
        })
        .collect()
}

/// The glossy sphere's pixels within 5% of the image width of one that reflects the light
/// (reference luminance above 1, brighter than any diffuse surface of the scene).
fn highlight_pixels(sphere: &[usize], reference: &[[f32; 3]], (w, _): (u32, u32)) -> Vec<usize> {
    let w = w as usize;
    let reach = (w / 20).max(1);
    let core: Vec<usize> = sphere
        .iter()
        .copied()
        .filter(|&i| luminance(reference[i]) > 1.0)
        .collect();
    sphere
        .iter()
        .copied()
        .filter(|&i| {
            core.iter()
                .any(|&j| (i % w).abs_diff(j % w) <= reach && (i / w).abs_diff(j / w) <= reach)
        })
        .collect()
}

/// The pixels whose centre's pinhole ray meets the default scene's glossy sphere within 90%
/// of its radius (away from its rim, which the lens blurs into the background).
fn glossy_sphere_pixels(data: &scenes::SceneData<'_>, (w, h): (u32, u32)) -> Vec<usize> {
    let Some(sphere) = data.objects.iter().find_map(|o| match o.shape {
        scenes::ShapeRange::Spheres { first, .. }
            if matches!(
                data.materials.get(o.material as usize),
                Some(Material::Glossy { .. })
            ) =>
        {
            data.spheres.get(first as usize)
        }
        _ => None,
    }) else {
        return Vec::new();
    };
    let c = data.camera;
    let v = |a: [f32; 3]| DVec3::from_array(a.map(f64::from));
    let eye = v(c.eye);
    let forward = (v(c.look_at) - eye).normalize();
    let right = forward.cross(v(c.up)).normalize();
    let up = right.cross(forward);
    let half = (f64::from(c.vfov_deg).to_radians() / 2.0).tan();
    let aspect = f64::from(w) / f64::from(h);
    let to = v(sphere.center) - eye;
    let r = 0.9 * f64::from(sphere.radius);
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let sx = (2.0 * (f64::from(x) + 0.5) / f64::from(w) - 1.0) * half * aspect;
            let sy = (1.0 - 2.0 * (f64::from(y) + 0.5) / f64::from(h)) * half;
            let d = (forward + sx * right + sy * up).normalize();
            // Distance from the centre to the ray's line, for a sphere in front of the eye.
            let along = to.dot(d);
            along > 0.0 && to.length_squared() - along * along < r * r
        })
        .map(|(x, y)| (y * w + x) as usize)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const GREY: [f32; 3] = [0.1, 0.1, 0.1];

    /// A 5×5 image of `GREY` with `value` at the centre.
    fn spike(value: f32) -> Vec<[f32; 3]> {
        let mut im = vec![GREY; 25];
        im[12] = [value; 3];
        im
    }

    #[test]
    fn a_lone_bright_pixel_is_the_only_firefly() {
        let flags = isolated_fireflies(&spike(0.4), &[GREY; 25], (5, 5));
        let found: Vec<usize> = (0..25).filter(|&i| flags[i]).collect();
        assert_eq!(found, [12]);
    }

    #[test]
    fn a_bright_pixel_in_equally_noisy_surroundings_is_not_isolated() {
        let reference = [GREY; 25];
        let mut im = spike(0.4);
        for i in [6, 7, 8, 11, 13, 16, 17, 18] {
            im[i] = [0.3; 3];
        }
        assert!(!isolated_fireflies(&im, &reference, (5, 5))[12]);
    }

    #[test]
    fn a_pixel_less_than_twice_its_reference_is_noise_not_a_firefly() {
        // 0.19 shows 0.1 brighter on an 8-bit display, but is under 2 × 0.1.
        let flags = isolated_fireflies(&spike(0.19), &[GREY; 25], (5, 5));
        assert!(display([0.19; 3]) - display(GREY) > VISIBLE);
        assert!(flags.iter().all(|&f| !f));
    }

    #[test]
    fn a_dark_pixel_is_never_a_firefly() {
        let flags = isolated_fireflies(&spike(0.0), &[GREY; 25], (5, 5));
        assert!(flags.iter().all(|&f| !f));
    }

    #[test]
    fn the_glossy_sphere_lies_right_of_centre_below_the_middle() {
        let px = glossy_sphere_pixels(&scenes::CORNELL, (64, 64));
        assert!(px.len() > 100, "{} pixels", px.len());
        // Its centre (0.45, 0.35, 0.3) is right of and below the view's centre.
        assert!(px.iter().all(|&i| i % 64 >= 32 && i / 64 >= 32));
    }

    #[test]
    fn the_highlight_is_the_bright_sphere_pixels_and_their_neighbourhood() {
        // A 40×40 image; the sphere is columns 10..30 of row 20, one pixel of it bright.
        let sphere: Vec<usize> = (10..30).map(|x| 20 * 40 + x).collect();
        let mut reference = vec![GREY; 1600];
        reference[20 * 40 + 15] = [5.0; 3];
        // Bright, but not on the sphere: not a highlight.
        reference[5] = [5.0; 3];
        let got = highlight_pixels(&sphere, &reference, (40, 40));
        let want: Vec<usize> = (13..=17).map(|x| 20 * 40 + x).collect();
        assert_eq!(got, want);
    }
}
