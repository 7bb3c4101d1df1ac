//! Noise of the default scene's glossy highlight under each integrator.
//!
//! `cargo run --release -p raykernel --features path-tracing --example highlight_noise --
//! [SPP] [SEEDS]` renders `scenes::CORNELL` at 64×64 (`f32`, the BVH family, Sobol samples) with
//! the direct integrator and the path integrator (5 segments). Each gets a reference at 16× `SPP`
//! (seed 0) and `SEEDS` renders at `SPP` (seeds 1..=SEEDS). It prints, per pixel of the 8×8
//! window around the glossy sphere's highlight, the red channel's RMS error over those renders
//! against the reference, then the largest errors of the whole image in display space (sRGB of
//! the value clamped to [0, 1], RMS over the channels) with their pixel.

use raykernel::bvh::{nodes_needed, BuildOptions};
use raykernel::render::{
    scenes, Integrator, Object, ObjectSlot, RenderMemory, RenderStats, Renderer, Rgb, SamplerKind,
    Settings, Shape,
};
use raykernel::{AccelMemory, BvhFamily, Node, Sphere, Triangle};

const SIZE: u32 = 64;
/// The highlight's window at 64×64: columns 40..48, rows 36..44.
const WINDOW: (core::ops::Range<u32>, core::ops::Range<u32>) = (40..48, 36..44);

/// Linear pixels of the default scene, row by row, rendered on two threads.
fn render(spp: u32, integrator: Integrator, seed: u32) -> Vec<Rgb> {
    let data = scenes::CORNELL;
    let mut tris = vec![Triangle::<f32> { v: [[0.0; 3]; 3] }; data.triangles.len()];
    let mut spheres = vec![
        Sphere::<f32> {
            center: [0.0; 3],
            radius: 0.0
        };
        data.spheres.len()
    ];
    data.triangles_into(&mut tris).unwrap();
    data.spheres_into(&mut spheres).unwrap();
    let mut objects = vec![Object::new(Shape::Triangles(&[]), 0); data.objects.len()];
    let scene = data.scene(&tris, &spheres, &mut objects).unwrap();
    let n = data.objects.len();
    let mut slots = vec![ObjectSlot::<f32, BvhFamily>::EMPTY; n];
    let mut nodes =
        vec![Node::<f32>::EMPTY; nodes_needed(tris.len()) + nodes_needed(spheres.len()) + 4 * n];
    let mut ids = vec![0u32; tris.len() + spheres.len() + n];
    let memory = RenderMemory {
        objects: &mut slots,
        accel: AccelMemory {
            nodes: &mut nodes,
            words: &mut ids,
            ..AccelMemory::default()
        },
    };
    let settings = Settings {
        width: SIZE,
        height: SIZE,
        spp,
        integrator,
        sampler: SamplerKind::Sobol,
        seed: data.settings.seed.wrapping_add(seed),
        ..data.settings
    };
    let r = Renderer::new(&scene, settings, BuildOptions::default(), memory).unwrap();
    let half = SIZE / 2;
    std::thread::scope(|s| {
        let halves: Vec<_> = [0, half]
            .into_iter()
            .map(|top| {
                let r = &r;
                s.spawn(move || {
                    let mut stats = RenderStats::default();
                    (top..top + half)
                        .flat_map(|y| (0..SIZE).map(move |x| (x, y)))
                        .map(|(x, y)| r.pixel(x, y, &mut stats))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        halves.into_iter().flat_map(|h| h.join().unwrap()).collect()
    })
}

fn display(x: f32) -> f64 {
    let x = f64::from(x.clamp(0.0, 1.0));
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

fn main() {
    let arg = |i: usize, default: u32| {
        std::env::args()
            .nth(i)
            .and_then(|s| s.parse().ok())
            .unwrap_or(default)
    };
    let (spp, seeds) = (arg(1, 256), arg(2, 4).max(1));
    let at = |x: u32, y: u32| (y * SIZE + x) as usize;
    for (name, integrator) in [
        ("direct", Integrator::Direct),
        ("path", Integrator::Path { max_length: 5 }),
    ] {
        let reference = render(spp * 16, integrator, 0);
        let renders: Vec<_> = (1..=seeds).map(|s| render(spp, integrator, s)).collect();
        let mean_sq = |i: usize, error: &dyn Fn(&Rgb, &Rgb) -> f64| {
            renders
                .iter()
                .map(|im| error(&im[i], &reference[i]))
                .sum::<f64>()
                / f64::from(seeds)
        };
        println!(
            "{name}: red-channel RMS error over {seeds} renders at {spp} spp against {} spp \
             (reference value in brackets)",
            spp * 16
        );
        for y in WINDOW.1.clone() {
            let row: Vec<String> = WINDOW
                .0
                .clone()
                .map(|x| {
                    let red = |p: &Rgb, q: &Rgb| f64::from(p[0] - q[0]).powi(2);
                    let i = at(x, y);
                    format!("{:.3}({:.1})", mean_sq(i, &red).sqrt(), reference[i][0])
                })
                .collect();
            println!("  y {y:2}: {}", row.join(" "));
        }
        let shown = |p: &Rgb, q: &Rgb| {
            p.iter()
                .zip(q)
                .map(|(a, b)| (display(*a) - display(*b)).powi(2))
                .sum::<f64>()
                / 3.0
        };
        let mut worst: Vec<(f64, usize)> = (0..reference.len())
            .map(|i| (mean_sq(i, &shown).sqrt(), i))
            .collect();
        worst.sort_by(|a, b| b.0.total_cmp(&a.0));
        for (error, i) in worst.iter().take(5) {
            let (x, y) = (*i as u32 % SIZE, *i as u32 / SIZE);
            println!(
                "  display error {error:.4} at ({x}, {y}), reference {:?}",
                reference[*i]
            );
        }
    }
}
