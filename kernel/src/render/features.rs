//! Parts of the renderer named at compile time, so that firmware links only what its scenes use.

use core::fmt::Debug;

/// The parts of the renderer a build links beyond its core (pinhole and thin-lens camera, box
/// filter, rectangle lights, diffuse, mirror, glossy and emissive materials, motion, both
/// integrators as the kernel's features allow). A constant `false` leaves that part out:
/// [`crate::render::Renderer::new`] refuses a scene or settings that need it with
/// [`crate::render::Problem::NotLinked`], and its code is not linked. [`AllFeatures`], the
/// default, links everything; firmware names its own type with the parts its scenes use.
pub trait RenderFeatures: Copy + Debug + 'static {
    /// The tent and Gaussian pixel filters ([`crate::render::Filter`]).
    const FILTERS: bool;
    /// Point lights ([`crate::render::Light::Point`]).
    const POINT_LIGHTS: bool;
    /// Sphere lights ([`crate::render::Light::Sphere`]).
    const SPHERE_LIGHTS: bool;
    /// Emissive geometry: objects with an [`crate::render::Object::emission`] or an emissive
    /// material, seen and sampled as area lights.
    const EMISSIVE_GEOMETRY: bool;
    /// One-sided objects ([`crate::render::Object::one_sided`]).
    const ONE_SIDED: bool;
    /// Smooth shading by vertex normals ([`crate::render::Object::vertex_normals`]).
    const SMOOTH_SHADING: bool;
    /// The first-hit loop for plans of camera rays only
    /// ([`crate::render::RenderPlan::camera_rays_only`]). A speed-up, not a feature: without it
    /// those scenes render through the general loop, to the same bits.
    const FIRST_HIT_LOOP: bool;
}

/// Every part of the renderer.
#[derive(Clone, Copy, Debug, Default)]
pub struct AllFeatures;

impl RenderFeatures for AllFeatures {
    const FILTERS: bool = true;
    const POINT_LIGHTS: bool = true;
    const SPHERE_LIGHTS: bool = true;
    const EMISSIVE_GEOMETRY: bool = true;
    const ONE_SIDED: bool = true;
    const SMOOTH_SHADING: bool = true;
    const FIRST_HIT_LOOP: bool = true;
}
