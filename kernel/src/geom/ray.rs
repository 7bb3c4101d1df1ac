use crate::scalar::RayError;
use crate::scalar::Scalar;

/// [`RayError::InvalidInterval`] unless `0 <= t_min <= t_max` with `t_min` finite (`f32`
/// bounds, before conversion to the mode).
#[inline(always)]
fn check_f32_interval(t_min: f32, t_max: f32) -> Result<(), RayError> {
    if t_min >= 0.0 && t_min.is_finite() && t_max >= t_min {
        Ok(())
    } else {
        Err(RayError::InvalidInterval)
    }
}

/// A half-line `origin + t·dir` for `t` in `[t_min, t_max]`, with its precomputed test data.
///
/// The direction is normalised by the constructors, so `t` is a distance in both modes.
/// Invariant: `0 <= t_min <= t_max`, `t_min` finite, no NaN anywhere; the precomputed data
/// (inverse direction, shear) never holds NaN.
#[derive(Clone, Copy, Debug)]
pub struct Ray<S: Scalar> {
    data: S::RayData,
    t_min: S,
    t_max: S,
}

impl<S: Scalar> Ray<S> {
    /// A ray over `[0, S::FAR]`.
    ///
    /// # Errors
    /// [`RayError::Origin`] for a non-finite or out-of-range origin, [`RayError::ZeroDirection`]
    /// and [`RayError::NonFiniteDirection`] for an unusable direction.
    // Hosted targets: always inlined, like the per-mode constructors under it, since a ray
    // returned through memory and then moved stalls its first reader on store forwarding (see
    // `ray_data` for `f32`). Bare-metal targets: one copy out of line, which builds the
    // per-mode data in place; inlined, each call site moved the returned data with a memcpy.
    #[cfg_attr(not(target_os = "none"), inline(always))]
    #[cfg_attr(target_os = "none", inline(never))]
    pub fn new(origin: S::Vec3, dir: S::Vec3) -> Result<Self, RayError> {
        let data = S::ray_data(S::vec_to_array(origin), S::vec_to_array(dir))?;
        Ok(Self {
            data,
            t_min: S::ZERO,
            t_max: S::FAR,
        })
    }

    /// A ray from `f32` components over `[t_min, t_max]` (`t_max` may be `+inf`; fixed point
    /// saturates it). In fixed-point mode the direction keeps 30 fraction bits.
    ///
    /// # Errors
    /// As [`Ray::new`], plus [`RayError::InvalidInterval`].
    // Inlined or not as `Ray::new` is, for the same reasons.
    #[cfg_attr(not(target_os = "none"), inline(always))]
    #[cfg_attr(target_os = "none", inline(never))]
    pub fn from_f32(
        origin: [f32; 3],
        dir: [f32; 3],
        t_min: f32,
        t_max: f32,
    ) -> Result<Self, RayError> {
        check_f32_interval(t_min, t_max)?;
        let data = S::ray_data_from_f32(origin, dir)?;
        Ok(Self {
            data,
            t_min: S::from_f32_saturating(t_min),
            t_max: S::from_f32_saturating(t_max),
        })
    }

    /// Makes this ray [`Ray::from_f32`]`(origin, dir, t_min, t_max)`, bit for bit; on error it
    /// is unchanged. A loop that traces many records through one `Ray` set this way pays less
    /// per query than one that constructs each: in `f32` the data is written in place, never
    /// assembled elsewhere and moved.
    ///
    /// # Errors
    /// As [`Ray::from_f32`].
    #[cfg_attr(not(target_os = "none"), inline(always))]
    pub fn set_from_f32(
        &mut self,
        origin: [f32; 3],
        dir: [f32; 3],
        t_min: f32,
        t_max: f32,
    ) -> Result<(), RayError> {
        check_f32_interval(t_min, t_max)?;
        S::set_ray_data_from_f32(&mut self.data, origin, dir)?;
        self.t_min = S::from_f32_saturating(t_min);
        self.t_max = S::from_f32_saturating(t_max);
        Ok(())
    }

    /// The same ray over `[t_min, t_max]`.
    ///
    /// # Errors
    /// [`RayError::InvalidInterval`] unless `0 <= t_min <= t_max` with `t_min` finite.
    pub fn with_interval(self, t_min: S, t_max: S) -> Result<Self, RayError> {
        let finite = t_min < S::FAR || t_min == S::ZERO;
        if !(t_min >= S::ZERO && finite && t_max >= t_min) {
            return Err(RayError::InvalidInterval);
        }
        Ok(Self {
            t_min,
            t_max,
            ..self
        })
    }

    /// The same ray (same direction bits and interval) from another origin.
    ///
    /// # Errors
    /// [`RayError::Origin`] for an unusable origin.
    pub fn moved(&self, origin: [S; 3]) -> Result<Self, RayError> {
        Ok(Self {
            data: S::ray_moved(&self.data, origin)?,
            ..*self
        })
    }

    /// The ray from the same origin along `dir` (`f32` components), over the same interval:
    /// the same bits as [`Ray::from_f32`] from this ray's origin would give, without checking
    /// and preparing the origin again. A pinhole camera's rays all share its eye.
    ///
    /// # Errors
    /// [`RayError::ZeroDirection`] and [`RayError::NonFiniteDirection`].
    #[cfg_attr(not(target_os = "none"), inline(always))]
    pub fn redirected_f32(&self, dir: [f32; 3]) -> Result<Self, RayError> {
        Ok(Self {
            data: S::ray_redirected_f32(&self.data, dir)?,
            ..*self
        })
    }

    /// Origin.
    pub fn origin(&self) -> S::Vec3 {
        S::array_to_vec(S::ray_origin(&self.data))
    }
    /// Unit direction (rounded to `S`; fixed point keeps more bits internally).
    pub fn dir(&self) -> S::Vec3 {
        S::array_to_vec(S::ray_dir(&self.data))
    }
    /// Start of the interval.
    pub fn t_min(&self) -> S {
        self.t_min
    }
    /// End of the interval.
    pub fn t_max(&self) -> S {
        self.t_max
    }
    /// Precomputed test data, for primitive implementations.
    pub fn data(&self) -> &S::RayData {
        &self.data
    }
}
