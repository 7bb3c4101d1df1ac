//! Global illumination against an independent renderer. A Cornell box (diffuse walls and two
//! blocks, a square light in a hole of the ceiling, paths of 5 segments: 4 bounces) renders
//! with the path integrator at doubling sample counts, single-threaded and timed, with each of
//! our samplers; Mitsuba 3 (`scalar_rgb`, one thread, through `scripts/mitsuba_render.py`)
//! renders the same scene file with its samplers. Every image's RMSE is taken against both
//! renderers' high-sample references, so the report shows each converging and whether the
//! two converge to the same image (the references' difference against their noise).

use crate::error::Error;
use host::scenefile::dump;
use raykernel::render::scenes::{ObjectData, SceneData, ShapeRange};
use raykernel::render::{Camera, Filter, Integrator, Light, Material, SamplerKind, Settings};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Segments per path: the camera ray and 4 bounces.
pub const PATH_LENGTH: u32 = 5;

/// What to render.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GiOptions {
    /// Image width and height in pixels.
    pub size: (u32, u32),
    /// Sample counts measured.
    pub spps: Vec<u32>,
    /// Samples per pixel of both references.
    pub reference_spp: u32,
    /// Threads for the (untimed) references.
    pub threads: usize,
    /// Where the scene file and Mitsuba's images go.
    pub work_dir: PathBuf,
}

impl GiOptions {
    /// 96×96 pixels (`--quick`: 24×24), 1, 2, 4, … up to 256 samples (`--quick`: 16),
    /// references 16 times the largest.
    #[must_use]
    pub fn new(quick: bool, threads: usize, work_dir: PathBuf) -> Self {
        let (size, top) = if quick {
            ((24, 24), 16)
        } else {
            ((96, 96), 256)
        };
        Self {
            size,
            spps: (0..31)
                .map(|k| 1u32 << k)
                .take_while(|&s| s <= top)
                .collect(),
            reference_spp: top * 16,
            threads,
            work_dir,
        }
    }
}

/// One measured render.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GiRow {
    /// `raykernel` or `mitsuba`.
    pub renderer: String,
    /// Sampler name.
    pub sampler: String,
    /// Samples per pixel.
    pub spp: u32,
    /// Render wall time (one thread), seconds.
    pub seconds: f64,
    /// RMSE of the linear image against our reference.
    pub rmse_ours: f64,
    /// RMSE against Mitsuba's reference (`None` without Mitsuba).
    pub rmse_mitsuba: Option<f64>,
}

/// The section's results.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GiResults {
    /// Image size.
    pub size: (u32, u32),
    /// Samples per pixel of each reference.
    pub reference_spp: u32,
    /// Every render.
    pub rows: Vec<GiRow>,
    /// Mitsuba's version, or why it did not run.
    pub mitsuba: Result<String, String>,
    /// RMSE between the two references.
    pub reference_difference: Option<f64>,
    /// The difference two unbiased references would show from their noise alone:
    /// `sqrt(n_ours² + n_mitsuba²)`, each reference's noise estimated from its independent
    /// sampler's error at the largest sample count (error ∝ spp^-1/2).
    pub reference_noise: Option<f64>,
    /// Mean of each channel over the image: our reference, then Mitsuba's.
    pub channel_means: Vec<[f64; 3]>,
}

/// The scene as owned data, with its material names (for the scene file).
pub struct GiScene {
    triangles: Vec<[[f32; 3]; 3]>,
    objects: Vec<ObjectData>,
    materials: Vec<Material>,
    names: Vec<String>,
    lights: Vec<Light>,
    camera: Camera,
    settings: Settings,
}

/// The half width of the light's square (centred in the ceiling at `y = 2`).
const LIGHT_HALF: f32 = 0.25;

impl GiScene {
    /// The box `[-1, 1] × [0, 2] × [-1, 1]`, open towards the camera at `z = 3.4`.
    #[must_use]
    pub fn cornell(width: u32, height: u32) -> Self {
        let white = [0.725, 0.71, 0.68];
        let red = [0.63, 0.065, 0.05];
        let green = [0.14, 0.45, 0.091];
        let mut s = Self {
            triangles: Vec::new(),
            objects: Vec::new(),
            materials: [white, red, green]
                .map(|albedo| Material::Diffuse { albedo })
                .to_vec(),
            names: ["white", "red", "green"].map(String::from).to_vec(),
            lights: vec![Light::Rect {
                corner: [-LIGHT_HALF, 2.0, -LIGHT_HALF],
                edge_u: [2.0 * LIGHT_HALF, 0.0, 0.0],
                edge_v: [0.0, 0.0, 2.0 * LIGHT_HALF],
                radiance: [17.0, 12.0, 4.0],
            }],
            camera: Camera {
                eye: [0.0, 1.0, 3.4],
                look_at: [0.0, 1.0, 0.0],
                up: [0.0, 1.0, 0.0],
                vfov_deg: 40.0,
                aperture_radius: 0.0,
                focus_distance: 3.4,
            },
            settings: Settings {
                width,
                height,
                spp: 1,
                max_depth: 0,
                integrator: Integrator::Path {
                    max_length: PATH_LENGTH,
                },
                filter: Filter::Box,
                ..Settings::default()
            },
        };
        let (l, h) = (LIGHT_HALF, 2.0);
        let quad = |a: [f32; 3], b: [f32; 3], c: [f32; 3], d: [f32; 3]| [[a, b, c], [a, c, d]];
        // Floor, back wall, and the ceiling around the light's square.
        s.add(
            0,
            &[
                quad(
                    [-1.0, 0.0, -1.0],
                    [-1.0, 0.0, 1.0],
                    [1.0, 0.0, 1.0],
                    [1.0, 0.0, -1.0],
                ),
                quad(
                    [-1.0, 0.0, -1.0],
                    [1.0, 0.0, -1.0],
                    [1.0, h, -1.0],
                    [-1.0, h, -1.0],
                ),
                quad([-1.0, h, -1.0], [1.0, h, -1.0], [1.0, h, -l], [-1.0, h, -l]),
                quad([-1.0, h, l], [1.0, h, l], [1.0, h, 1.0], [-1.0, h, 1.0]),
                quad([-1.0, h, -l], [-l, h, -l], [-l, h, l], [-1.0, h, l]),
                quad([l, h, -l], [1.0, h, -l], [1.0, h, l], [l, h, l]),
            ],
        );
        s.add(
            1,
            &[quad(
                [-1.0, 0.0, -1.0],
                [-1.0, h, -1.0],
                [-1.0, h, 1.0],
                [-1.0, 0.0, 1.0],
            )],
        );
        s.add(
            2,
            &[quad(
                [1.0, 0.0, -1.0],
                [1.0, 0.0, 1.0],
                [1.0, h, 1.0],
                [1.0, h, -1.0],
            )],
        );
        s.add(0, &block([-0.35, -0.3], 0.3, 1.2, 0.3));
        s.add(0, &block([0.4, 0.35], 0.3, 0.6, -0.3));
        s
    }

    fn add(&mut self, material: u32, quads: &[[[[f32; 3]; 3]; 2]]) {
        let first = self.triangles.len();
        self.triangles.extend(quads.iter().flatten());
        self.objects.push(ObjectData {
            shape: ShapeRange::Triangles {
                first: u32::try_from(first).unwrap_or(u32::MAX),
                count: u32::try_from(quads.len() * 2).unwrap_or(u32::MAX),
            },
            material,
            motion: [0.0; 3],
            emission: [0.0; 3],
            one_sided: false,
        });
    }

    /// The kernel's view, rendered with `settings`.
    #[must_use]
    pub fn data(&self) -> SceneData<'_> {
        SceneData {
            name: "gi-cornell",
            triangles: &self.triangles,
            vertex_normals: &[],
            spheres: &[],
            objects: &self.objects,
            materials: &self.materials,
            lights: &self.lights,
            camera: self.camera,
            background: [0.0; 3],
            settings: self.settings,
        }
    }

    /// The scene file Mitsuba reads.
    #[must_use]
    pub fn file_text(&self) -> String {
        dump(&self.data(), &self.names)
    }
}

/// A block on the floor: square footprint of half width `half` centred at `(x, z)`, rotated
/// by `turn` radians about y, `height` tall; its four sides and top.
fn block(centre: [f32; 2], half: f32, height: f32, turn: f32) -> Vec<[[[f32; 3]; 3]; 2]> {
    let (sin, cos) = turn.sin_cos();
    let at = |dx: f32, dz: f32, y: f32| {
        [
            centre[0] + cos * dx - sin * dz,
            y,
            centre[1] + sin * dx + cos * dz,
        ]
    };
    let corners = [(-half, -half), (half, -half), (half, half), (-half, half)];
    let mut quads = Vec::new();
    for k in 0..4 {
        let (a, b) = (corners[k], corners[(k + 1) % 4]);
        quads.push([
            [at(a.0, a.1, 0.0), at(b.0, b.1, 0.0), at(b.0, b.1, height)],
            [
                at(a.0, a.1, 0.0),
                at(b.0, b.1, height),
                at(a.0, a.1, height),
            ],
        ]);
    }
    let top = corners.map(|(x, z)| at(x, z, height));
    quads.push([[top[0], top[1], top[2]], [top[0], top[2], top[3]]]);
    quads
}

/// What `mitsuba_render.py` writes.
#[derive(Deserialize)]
struct MitsubaOutput {
    version: String,
    renders: Vec<MitsubaRender>,
    reference: MitsubaRender,
}

#[derive(Deserialize)]
struct MitsubaRender {
    sampler: String,
    spp: u32,
    #[serde(default)]
    seconds: f64,
    file: String,
}

/// Renders ours, runs Mitsuba (when `python3` can import it), and compares.
///
/// # Errors
/// A render the kernel refuses, or an unwritable work directory. Mitsuba missing or failing is
/// not an error: the results say why it did not run.
pub fn run(opts: &GiOptions) -> Result<GiResults, Error> {
    let scene = GiScene::cornell(opts.size.0, opts.size.1);
    let data = scene.data();
    let go = |sampler, spp, threads| {
        let settings = Settings {
            spp,
            sampler,
            ..data.settings
        };
        crate::images::render_f32(&data, settings, threads)
    };
    eprintln!(
        "bench: global illumination: {}x{}, references {} spp",
        opts.size.0, opts.size.1, opts.reference_spp
    );
    let reference = go(SamplerKind::Sobol, opts.reference_spp, opts.threads)?
        .frame
        .linear;
    let mut ours = Vec::new();
    for sampler in SamplerKind::ALL {
        for &spp in &opts.spps {
            let r = go(sampler, spp, 1)?;
            ours.push((
                sampler.name().to_string(),
                spp,
                r.render_ms / 1e3,
                r.frame.linear,
            ));
        }
    }
    std::fs::create_dir_all(&opts.work_dir)
        .map_err(|e| Error::Bench(format!("cannot create {}: {e}", opts.work_dir.display())))?;
    let mitsuba = run_mitsuba(&scene, opts);
    let pixels = (opts.size.0 * opts.size.1) as usize;
    let mut results = GiResults {
        size: opts.size,
        reference_spp: opts.reference_spp,
        rows: Vec::new(),
        mitsuba: Err(String::new()),
        reference_difference: None,
        reference_noise: None,
        channel_means: vec![channel_means(&reference)],
    };
    let (theirs, their_reference) = match mitsuba.and_then(|m| read_mitsuba(m, opts, pixels)) {
        Ok((version, renders, r)) => {
            results.mitsuba = Ok(version);
            (renders, Some(r))
        }
        Err(why) => {
            eprintln!("bench:   Mitsuba skipped: {why}");
            results.mitsuba = Err(why);
            (Vec::new(), None)
        }
    };
    let against = |image: &[[f32; 3]]| {
        (
            crate::images::rmse(&reference, image),
            their_reference
                .as_deref()
                .map(|r| crate::images::rmse(r, image)),
        )
    };
    for (renderer, list) in [("raykernel", &ours), ("mitsuba", &theirs)] {
        for (sampler, spp, seconds, image) in list {
            let (rmse_ours, rmse_mitsuba) = against(image);
            results.rows.push(GiRow {
                renderer: renderer.into(),
                sampler: sampler.clone(),
                spp: *spp,
                seconds: *seconds,
                rmse_ours,
                rmse_mitsuba,
            });
        }
    }
    if let Some(r) = &their_reference {
        results.channel_means.push(channel_means(r));
        results.reference_difference = Some(crate::images::rmse(&reference, r));
        let top = opts.spps.last().copied().unwrap_or(1);
        let noise = |renderer: &str, own: fn(&GiRow) -> Option<f64>| {
            let row = results
                .rows
                .iter()
                .find(|x| x.renderer == renderer && x.sampler == "independent" && x.spp == top)?;
            // error(top)² = σ²/top + σ²/reference: the reference's own share.
            let share = f64::from(top) / f64::from(opts.reference_spp);
            Some(own(row)? * (share / (1.0 + share)).sqrt())
        };
        if let (Some(a), Some(b)) = (
            noise("raykernel", |x| Some(x.rmse_ours)),
            noise("mitsuba", |x| x.rmse_mitsuba),
        ) {
            results.reference_noise = Some(a.hypot(b));
        }
    }
    Ok(results)
}

type Image = Vec<[f32; 3]>;

/// Writes the scene file and runs the script; its output directory on success.
fn run_mitsuba(scene: &GiScene, opts: &GiOptions) -> Result<PathBuf, String> {
    let file = opts.work_dir.join("gi-cornell.json");
    std::fs::write(&file, scene.file_text())
        .map_err(|e| format!("cannot write {}: {e}", file.display()))?;
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/mitsuba_render.py");
    let spps: Vec<String> = opts.spps.iter().map(u32::to_string).collect();
    let out = opts.work_dir.join("mitsuba");
    eprintln!("bench:   Mitsuba 3 ({})", script.display());
    let status = Command::new("python3")
        .arg(&script)
        .arg(&file)
        .arg(&out)
        .arg("--spp")
        .arg(spps.join(","))
        .arg("--reference-spp")
        .arg(opts.reference_spp.to_string())
        .arg("--reference-threads")
        .arg(opts.threads.to_string())
        .status()
        .map_err(|e| format!("cannot run python3: {e}"))?;
    if status.success() {
        Ok(out)
    } else {
        Err(format!(
            "{} failed ({status}); it needs `pip install mitsuba`",
            script.display()
        ))
    }
}

type MitsubaImages = (String, Vec<(String, u32, f64, Image)>, Image);

fn read_mitsuba(dir: PathBuf, opts: &GiOptions, pixels: usize) -> Result<MitsubaImages, String> {
    let text = std::fs::read_to_string(dir.join("mitsuba.json"))
        .map_err(|e| format!("no mitsuba.json: {e}"))?;
    let out: MitsubaOutput =
        serde_json::from_str(&text).map_err(|e| format!("bad mitsuba.json: {e}"))?;
    let image = |r: &MitsubaRender| -> Result<Image, String> {
        let bytes = std::fs::read(dir.join(&r.file)).map_err(|e| format!("{}: {e}", r.file))?;
        if bytes.len() != pixels * 12 {
            return Err(format!(
                "{}: {} bytes, expected {}",
                r.file,
                bytes.len(),
                pixels * 12
            ));
        }
        Ok(bytes
            .chunks_exact(12)
            .map(|p| {
                core::array::from_fn(|c| {
                    f32::from_le_bytes([p[4 * c], p[4 * c + 1], p[4 * c + 2], p[4 * c + 3]])
                })
            })
            .collect())
    };
    let reference = image(&out.reference)?;
    if out.reference.spp != opts.reference_spp {
        return Err("the reference's sample count differs".into());
    }
    let renders = out
        .renders
        .iter()
        .map(|r| Ok((r.sampler.clone(), r.spp, r.seconds, image(r)?)))
        .collect::<Result<_, String>>()?;
    Ok((out.version, renders, reference))
}

fn channel_means(image: &[[f32; 3]]) -> [f64; 3] {
    let n = image.len().max(1) as f64;
    core::array::from_fn(|c| image.iter().map(|p| f64::from(p[c])).sum::<f64>() / n)
}

/// The time at which a renderer's error curve (one sampler: `(seconds, rmse)` by increasing
/// samples) first reaches `target`, interpolated log-linearly between the measured renders;
/// `None` if it never does.
#[must_use]
pub fn time_to_reach(curve: &[(f64, f64)], target: f64) -> Option<f64> {
    let first = curve.first()?;
    if first.1 <= target {
        return Some(first.0);
    }
    curve.windows(2).find_map(|w| {
        let ((t0, e0), (t1, e1)) = (w[0], w[1]);
        if e1 > target || !(e0 > 0.0 && e1 > 0.0 && t0 > 0.0 && t1 > 0.0) {
            return None;
        }
        // log t linear in log e between the two points.
        let f = (target.ln() - e0.ln()) / (e1.ln() - e0.ln());
        Some((t0.ln() + f * (t1.ln() - t0.ln())).exp())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_to_reach_interpolates_on_log_axes() {
        // Error halves each time the time quadruples (∝ t^-1/2).
        let curve = [(1.0, 0.4), (4.0, 0.2), (16.0, 0.1)];
        assert_eq!(time_to_reach(&curve, 0.5), Some(1.0));
        let t = time_to_reach(&curve, 0.2 / 2f64.sqrt()).unwrap();
        assert!((t - 8.0).abs() < 1e-9, "{t}");
        assert_eq!(time_to_reach(&curve, 0.05), None);
    }

    /// The quick comparison: both references agree within their noise. Needs `python3` with
    /// Mitsuba 3 (`pip install mitsuba`); without it the test says skipped.
    #[test]
    fn ours_and_mitsuba_converge_to_the_same_image() {
        let work = std::env::temp_dir().join(format!("raykernel-gi-test-{}", std::process::id()));
        let opts = GiOptions::new(true, 2, work.clone());
        let r = run(&opts).unwrap();
        let _ = std::fs::remove_dir_all(&work);
        if let Err(why) = &r.mitsuba {
            println!("skipped: Mitsuba did not run: {why}");
            return;
        }
        let (d, n) = (r.reference_difference.unwrap(), r.reference_noise.unwrap());
        assert!(d < 2.0 * n, "references differ by {d}, noise {n}");
        for (c, (a, b)) in r.channel_means[0]
            .iter()
            .zip(r.channel_means[1])
            .enumerate()
        {
            assert!(
                (a - b).abs() < 0.02 * a.max(b),
                "channel {c}: {a} against {b}"
            );
        }
    }

    #[test]
    fn the_scene_is_closed_but_for_the_front_and_the_light() {
        let s = GiScene::cornell(8, 8);
        // Floor, back wall, 4 ceiling pieces, 2 side walls, 2 blocks of 5 sides.
        assert_eq!(s.triangles.len(), 2 * (1 + 1 + 4 + 1 + 1 + 5 + 5));
        // The ceiling pieces and the light tile the ceiling: 4 - light area.
        let ceiling: f64 = s
            .triangles
            .iter()
            .filter(|t| t.iter().all(|p| p[1] == 2.0))
            .map(|t| {
                let (a, b, c) = (t[0], t[1], t[2]);
                let u = [b[0] - a[0], b[2] - a[2]];
                let v = [c[0] - a[0], c[2] - a[2]];
                f64::from((u[0] * v[1] - u[1] * v[0]).abs()) / 2.0
            })
            .sum();
        let light = f64::from(2.0 * LIGHT_HALF).powi(2);
        assert!((ceiling + light - 4.0).abs() < 1e-6, "{ceiling}");
    }
}
