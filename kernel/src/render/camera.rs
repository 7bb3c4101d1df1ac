//! Camera rays: pinhole or thin lens.

use super::sampling::{concentric_disk, sin_cos_turns};
use super::scene::{finite3, Camera, Item, Problem, SceneError};
use super::vector;
use crate::geom::Ray;
use crate::scalar::Scalar;
use glam::Vec3;

/// A camera's frame for one image size.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CameraFrame {
    eye: Vec3,
    /// Unit view direction.
    w: Vec3,
    /// Unit right vector scaled by half the image plane's width at distance 1.
    u: Vec3,
    /// Unit up vector scaled by half the image plane's height at distance 1.
    v: Vec3,
    /// Unit right and up (for the lens).
    right: Vec3,
    up: Vec3,
    lens_radius: f32,
    focus: f32,
    inv_width: f32,
    inv_height: f32,
}

impl CameraFrame {
    pub(crate) fn new(c: &Camera, width: u32, height: u32) -> Result<Self, SceneError> {
        let err = |field, p| SceneError::new(Item::Camera, 0, field, p);
        for (field, v) in [("eye", c.eye), ("look_at", c.look_at), ("up", c.up)] {
            if !finite3(v) {
                return Err(err(field, Problem::NonFinite));
            }
        }
        if !(c.vfov_deg.is_finite()) {
            return Err(err("vfov_deg", Problem::NonFinite));
        }
        if !(c.vfov_deg > 0.0 && c.vfov_deg < 180.0) {
            let p = Problem::OutOfRange {
                min: 0.0,
                max: 180.0,
            };
            return Err(err("vfov_deg", p));
        }
        if !c.aperture_radius.is_finite() {
            return Err(err("aperture_radius", Problem::NonFinite));
        }
        if c.aperture_radius < 0.0 {
            return Err(err("aperture_radius", Problem::Negative));
        }
        if c.aperture_radius > 0.0 && !(c.focus_distance.is_finite() && c.focus_distance > 0.0) {
            let p = if c.focus_distance.is_finite() {
                Problem::NotPositive
            } else {
                Problem::NonFinite
            };
            return Err(err("focus_distance", p));
        }
        let eye = Vec3::from_array(c.eye);
        let w = vector::normalize_or_zero(Vec3::from_array(c.look_at) - eye);
        if w == Vec3::ZERO {
            return Err(err("look_at", Problem::Degenerate));
        }
        let right = vector::normalize_or_zero(w.cross(Vec3::from_array(c.up)));
        if right == Vec3::ZERO {
            return Err(err("up", Problem::Degenerate));
        }
        let up = right.cross(w);
        // Half the field of view, in turns: `vfov_deg / 2 / 360`.
        let (sin, cos) = sin_cos_turns(c.vfov_deg / 720.0);
        let half_h = sin / cos;
        let aspect = width as f32 / height as f32;
        Ok(Self {
            eye,
            w,
            u: right * (half_h * aspect),
            v: up * half_h,
            right,
            up,
            lens_radius: c.aperture_radius,
            focus: c.focus_distance,
            inv_width: 1.0 / width as f32,
            inv_height: 1.0 / height as f32,
        })
    }

    /// The pinhole's ray along the view direction; `None` if the eye is outside the mode's
    /// range (no camera ray is usable then).
    pub(crate) fn eye_ray<S: Scalar>(&self) -> Option<Ray<S>> {
        Ray::<S>::from_f32(self.eye.to_array(), self.w.to_array(), 0.0, f32::INFINITY).ok()
    }

    /// Origin and (unnormalised) direction of the ray through image position `(x, y)` (pixels,
    /// from the top-left corner) and lens sample `lens` in `[0, 1)²` (ignored for a pinhole).
    #[inline]
    pub(crate) fn ray(&self, x: f32, y: f32, lens: Option<(f32, f32)>) -> (Vec3, Vec3) {
        let sx = 2.0 * x * self.inv_width - 1.0;
        let sy = 1.0 - 2.0 * y * self.inv_height;
        let d = self.w + self.u * sx + self.v * sy;
        match lens {
            Some((a, b)) if self.lens_radius > 0.0 => {
                let (lx, ly) = concentric_disk(a, b);
                let offset = (self.right * lx + self.up * ly) * self.lens_radius;
                // The pinhole ray meets the plane of focus at `eye + focus·d` (d·w = 1).
                let target = d * self.focus;
                (self.eye + offset, target - offset)
            }
            _ => (self.eye, d),
        }
    }
}
