//! Lights as geometry: their visible surfaces, checked and converted to the mode.

use super::features::RenderFeatures;
use super::scene::{Light, Problem};
use crate::geom::spawn::{cross, unit};
use crate::geom::{Primitive, Sphere, Triangle};
use crate::scalar::Scalar;

/// Most lights a scene may have.
pub const MAX_LIGHTS: usize = 8;

/// A light's visible surface.
#[derive(Clone, Copy, Debug)]
pub(crate) enum LightGeom<S: Scalar> {
    /// Not visible.
    Point,
    /// Two triangles; the front side is the side `edge_u × edge_v` points to.
    Rect([Triangle<S>; 2], [f32; 3]),
    /// A sphere.
    Sphere(Sphere<S>),
}

/// Light `l`'s surface in mode `S`; kinds `K` leaves out are refused.
pub(super) fn light_geom<S: Scalar, K: RenderFeatures>(
    l: &Light,
) -> Result<LightGeom<S>, (&'static str, Problem)> {
    let pt = |p: [f32; 3], field| -> Result<[S; 3], (&'static str, Problem)> {
        let mut out = [S::ZERO; 3];
        for k in 0..3 {
            out[k] = S::coord_from_f32(p[k]).map_err(|e| (field, point_problem(e)))?;
        }
        Ok(out)
    };
    match *l {
        Light::Point { .. } if !K::POINT_LIGHTS => Err(("point", Problem::NotLinked)),
        Light::Sphere { .. } if !K::SPHERE_LIGHTS => Err(("sphere", Problem::NotLinked)),
        Light::Point {
            position,
            intensity,
        } => {
            pt(position, "position")?;
            super::scene::check_rgb(intensity, false).map_err(|p| ("intensity", p))?;
            Ok(LightGeom::Point)
        }
        Light::Rect {
            corner,
            edge_u,
            edge_v,
            radiance,
        } => {
            super::scene::check_rgb(radiance, false).map_err(|p| ("radiance", p))?;
            if !super::scene::finite3(edge_u) {
                return Err(("edge_u", Problem::NonFinite));
            }
            if !super::scene::finite3(edge_v) {
                return Err(("edge_v", Problem::NonFinite));
            }
            let n = cross(&edge_u.map(f64::from), &edge_v.map(f64::from));
            let Some(n) = unit(n) else {
                return Err(("edge_v", Problem::ZeroArea));
            };
            let add = |a: [f32; 3], b: [f32; 3]| core::array::from_fn(|k| a[k] + b[k]);
            let a = pt(corner, "corner")?;
            let b = pt(add(corner, edge_u), "edge_u")?;
            let c = pt(add(add(corner, edge_u), edge_v), "edge_v")?;
            let d = pt(add(corner, edge_v), "edge_v")?;
            Ok(LightGeom::Rect(
                [Triangle { v: [a, b, c] }, Triangle { v: [a, c, d] }],
                n.map(|x| x as f32),
            ))
        }
        Light::Sphere {
            center,
            radius,
            radiance,
        } => {
            super::scene::check_rgb(radiance, false).map_err(|p| ("radiance", p))?;
            if !radius.is_finite() {
                return Err(("radius", Problem::NonFinite));
            }
            if radius <= 0.0 {
                return Err(("radius", Problem::NotPositive));
            }
            let c = pt(center, "center")?;
            let r = S::coord_from_f32(radius).map_err(|e| ("radius", point_problem(e)))?;
            let s = Sphere {
                center: c,
                radius: r,
            };
            s.check().map_err(|e| ("radius", point_problem(e.error)))?;
            Ok(LightGeom::Sphere(s))
        }
    }
}

pub(crate) fn point_problem(e: crate::scalar::PointError) -> Problem {
    match e {
        crate::scalar::PointError::NonFinite => Problem::NonFinite,
        crate::scalar::PointError::OutOfRange { limit } => Problem::OutOfRange {
            min: -limit,
            max: limit,
        },
        crate::scalar::PointError::NegativeRadius => Problem::Negative,
    }
}
