//! The run's figures as long rows, one per (scene, rays, contender, figure): `data.json`'s
//! `figures` and `data.csv` are both written from [`figures`], so a script can recompute any
//! ratio without knowing the report's layout (`bench/scripts/ratios.py`).
//!
//! Names: `scene` is a scene name (`bunny`, `city`), `tiled-N` for the scale sweep or
//! `icosphere-256` for the render overhead; `rays` is `primary`, `incoherent` or `-`;
//! `contender` is the row's label (`raykernel bvh4 sah f32`, `Embree 3 HIGH`, ...);
//! `figure` names the quantity and its unit (`closest_mrays`, `build_ms`, ...).

use crate::report::BenchResults;
use crate::results::TraceRow;
use serde::Serialize;

/// One figure.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Figure {
    /// Scene.
    pub scene: String,
    /// Ray set, or `-`.
    pub rays: String,
    /// Contender label.
    pub contender: String,
    /// What is measured, with its unit in the name.
    pub figure: String,
    /// The value.
    pub value: f64,
}

/// Figure names of a trace row, with what they mean.
pub mod names {
    /// Closest hit, Mrays/s, each ray constructed from its record (the headline).
    pub const CLOSEST: &str = "closest_mrays";
    /// Closest hit of pre-built rays, Mrays/s.
    pub const CLOSEST_PREBUILT: &str = "closest_mrays_prebuilt";
    /// Any hit, Mrays/s, ray construction included.
    pub const ANY: &str = "any_mrays";
    /// Any hit of pre-built rays, Mrays/s.
    pub const ANY_PREBUILT: &str = "any_mrays_prebuilt";
    /// Round `k` (1-based) of the interleaved rounds: `closest_mrays_round{k}` (per ray) or
    /// `closest_mrays_prebuilt_round{k}`.
    pub const ROUND_PREFIX: &str = "round";
}

/// Every figure of the run, in a stable order.
#[must_use]
pub fn figures(r: &BenchResults) -> Vec<Figure> {
    let mut out = Vec::new();
    let mut push = |scene: &str, rays: &str, contender: &str, figure: &str, value: f64| {
        out.push(Figure {
            scene: scene.into(),
            rays: rays.into(),
            contender: contender.into(),
            figure: figure.into(),
            value,
        });
    };
    for x in &r.rows {
        let label = x.label();
        for (figure, value) in trace_figures(x) {
            push(&x.scene, x.rays.name(), &label, figure, value);
        }
    }
    for x in &r.rounds {
        let ours = x.ours.iter().flat_map(|o| {
            let contender = format!("raykernel {} sah f32", o.structure);
            [
                (contender.clone(), "closest_mrays", &o.per_ray_mrays),
                (contender, "closest_mrays_prebuilt", &o.prebuilt_mrays),
            ]
        });
        let peers = [
            (
                "Embree 3 HIGH".to_string(),
                "closest_mrays",
                &x.embree_mrays,
            ),
            (
                "Embree 3 HIGH robust".to_string(),
                "closest_mrays",
                &x.embree_robust_mrays,
            ),
            (
                "tinybvh 1.6 BVH2".to_string(),
                "closest_mrays_prebuilt",
                &x.tinybvh_mrays,
            ),
        ];
        let tinybvh8 = x
            .tinybvh8
            .iter()
            .map(|t| (t.name.to_string(), "closest_mrays_prebuilt", &t.mrays));
        for (contender, figure, values) in ours.chain(peers).chain(tinybvh8) {
            for (k, v) in values.iter().enumerate() {
                let name = format!("{figure}_{}{}", names::ROUND_PREFIX, k + 1);
                push(&x.scene, x.rays.name(), &contender, &name, *v);
            }
        }
        for t in &x.tinybvh8 {
            push(
                &x.scene,
                x.rays.name(),
                t.name,
                "same_prim_pct_vs_ours",
                t.same_prim_pct,
            );
        }
    }
    for x in &r.reference {
        push(
            &x.scene,
            x.rays.name(),
            "f64 reference",
            "rays",
            x.ray_count as f64,
        );
        push(
            &x.scene,
            x.rays.name(),
            "f64 reference",
            "hits",
            x.hits as f64,
        );
    }
    for x in &r.scale {
        let scene = format!("tiled-{}", x.triangles);
        let contender = format!("raykernel bvh {} {}", x.builder, x.mode);
        for (figure, value) in [
            ("triangles", x.triangles as f64),
            ("instances", x.instances as f64),
            ("build_ms", x.build_ms),
            ("bytes_per_tri", x.bytes_per_tri),
            ("rays", x.ray_count as f64),
        ] {
            push(&scene, "-", &contender, figure, value);
        }
        push(
            &scene,
            "primary",
            &contender,
            "closest_mrays_prebuilt",
            x.primary_mrays,
        );
        push(
            &scene,
            "incoherent",
            &contender,
            "closest_mrays_prebuilt",
            x.incoherent_mrays,
        );
        push(
            &scene,
            "incoherent",
            &contender,
            "nodes_per_ray",
            x.incoherent_nodes_per_ray,
        );
    }
    for x in &r.refit {
        let contender = format!("raykernel refit {} {}%", x.mode, x.amplitude * 100.0);
        for (figure, value) in [
            ("rebuild_ms", x.rebuild_ms),
            ("refit_bvh_ms", x.refit_bvh_ms),
            ("refit_bvh4_ms", x.refit_bvh4_ms),
            ("rebuilt_mrays_prebuilt", x.rebuilt_mrays),
            ("refitted_mrays_prebuilt", x.refitted_mrays),
            ("differing_hits", x.differing_hits as f64),
        ] {
            push(&x.scene, "primary", &contender, figure, value);
        }
    }
    for x in &r.overhead {
        let contender = format!("raykernel render {} {}", x.workload, x.mode);
        for (figure, value) in [
            ("bare_ms", x.bare_ms),
            ("renderer_ms", x.renderer_ms),
            ("overhead_pct", x.overhead_pct),
            ("differing_bytes", x.differing_bytes as f64),
        ] {
            push("icosphere-256", "-", &contender, figure, value);
        }
    }
    for x in &r.objects {
        let contender = format!("raykernel render objects {}", x.mode);
        let scene = format!("spheres-{}", x.spheres);
        for (figure, value) in [
            ("many_build_ms", x.many_build_ms),
            ("one_build_ms", x.one_build_ms),
            ("many_render_ms", x.many_render_ms),
            ("one_render_ms", x.one_render_ms),
            ("render_ratio", x.render_ratio),
            ("differing_bytes", x.differing_bytes as f64),
            (
                "differing_bytes_brute_force",
                x.differing_bytes_brute_force as f64,
            ),
        ] {
            push(&scene, "-", &contender, figure, value);
        }
    }
    for x in &r.images {
        let contender = format!("raykernel render {} {}spp", x.sampler, x.spp);
        push(&x.scene, "-", &contender, "seconds", x.seconds);
        push(&x.scene, "-", &contender, "rmse", x.rmse);
    }
    for x in &r.slopes {
        push(&x.plot, "-", &x.series, "slope", x.slope);
    }
    out
}

/// The figures of one trace row (absent ones left out).
fn trace_figures(x: &TraceRow) -> Vec<(&'static str, f64)> {
    let mut f = vec![
        ("rays", x.ray_count as f64),
        ("triangles", x.triangles as f64),
        ("build_ms", x.build_ms),
        ("setup_ns_per_ray", x.setup_ns_per_ray),
        (names::CLOSEST, x.closest_mrays),
        (names::ANY, x.any_mrays),
        ("bytes_per_tri", x.bytes_per_tri),
        ("hits", x.hits as f64),
        ("any_hits", x.any_hits as f64),
    ];
    let optional = [
        (names::CLOSEST_PREBUILT, x.closest_mrays_prebuilt),
        (names::ANY_PREBUILT, x.any_mrays_prebuilt),
        ("nodes_per_ray", x.nodes_per_ray),
        ("prims_per_ray", x.prims_per_ray),
        ("depth", x.depth.map(f64::from)),
    ];
    f.extend(optional.into_iter().filter_map(|(n, v)| Some((n, v?))));
    if let Some(c) = x.vs_ours {
        f.extend([
            ("agree_pct_vs_ours", c.agree_pct),
            ("ties_vs_ours", c.prim_only as f64),
            ("hitmiss_vs_ours", c.hitmiss as f64),
        ]);
    }
    if let Some(h) = x.hitmiss_split {
        f.extend([
            ("only_ours_hits", h.ours_only as f64),
            ("only_peer_hits", h.peer_only as f64),
        ]);
    }
    if let Some(a) = x.accuracy {
        f.extend([
            ("t_rel_max", a.t_rel_max),
            ("t_rel_mean", a.t_rel_mean),
            ("wrong_prim", a.wrong_prim as f64),
            ("ties", a.ties as f64),
            ("leaks", a.leaks as f64),
            ("false_hits", a.false_hits as f64),
        ]);
    }
    f
}

/// The CSV: a header, then one figure per line (`scene,rays,contender,figure,value`).
#[must_use]
pub fn csv_text(figures: &[Figure]) -> String {
    let mut s = String::from("scene,rays,contender,figure,value\n");
    for f in figures {
        s.push_str(&format!(
            "{},{},{},{},{}\n",
            f.scene, f.rays, f.contender, f.figure, f.value
        ));
    }
    s
}
