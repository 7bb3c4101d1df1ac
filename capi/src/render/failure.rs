//! A rejected input as the C side reports it: a status and the value at fault.

use super::types::*;
use crate::RkStatus;
use core::ffi::c_char;
use raykernel::render::{Item, Problem, SceneError};
use raykernel::BuildError;

/// A rejected input: the status and where.
#[derive(Clone, Copy, Debug)]
pub(super) struct Failure {
    pub(super) status: RkStatus,
    item: u32,
    index: usize,
    field: &'static str,
    range: (f32, f32),
}

impl Failure {
    pub(super) const fn new(
        status: RkStatus,
        item: u32,
        index: usize,
        field: &'static str,
    ) -> Self {
        Self {
            status,
            item,
            index,
            field,
            range: (0.0, 0.0),
        }
    }

    pub(super) const fn scene(status: RkStatus, field: &'static str) -> Self {
        Self::new(status, RK_ITEM_SCENE, 0, field)
    }

    /// The same value at fault with another status.
    pub(super) const fn with(self, status: RkStatus) -> Self {
        Self { status, ..self }
    }

    pub(super) fn to_c(self) -> RkSceneError {
        let mut field = [0 as c_char; RK_FIELD_LEN];
        for (slot, b) in field[..RK_FIELD_LEN - 1].iter_mut().zip(self.field.bytes()) {
            *slot = b as c_char;
        }
        RkSceneError {
            item: self.item,
            index: u32::try_from(self.index).unwrap_or(u32::MAX),
            field,
            min: self.range.0,
            max: self.range.1,
        }
    }
}

/// The status for a kernel error (`sphere`: the object named is a set of spheres).
pub(super) fn status_of(e: &SceneError, sphere: bool) -> RkStatus {
    let tile = e.item == Item::Tile;
    match e.problem {
        Problem::NonFinite => RkStatus::ErrNonFinite,
        Problem::Negative => RkStatus::ErrNegative,
        Problem::AboveOne => RkStatus::ErrAboveOne,
        Problem::NotPositive => RkStatus::ErrNotPositive,
        Problem::OutOfRange { .. } if tile => RkStatus::ErrBadTile,
        Problem::OutOfRange { .. } => RkStatus::ErrOutOfRange,
        Problem::ZeroArea => RkStatus::ErrZeroArea,
        Problem::Degenerate => RkStatus::ErrDegenerate,
        Problem::Index { .. } => RkStatus::ErrBadIndex,
        Problem::TooMany { .. } => RkStatus::ErrTooMany,
        Problem::TooSmall { .. } if tile => RkStatus::ErrBufferTooSmall,
        Problem::TooSmall { .. } => RkStatus::ErrMemoryTooSmall,
        Problem::Build(BuildError::BadPrimitive { .. }) if sphere => RkStatus::ErrBadSphere,
        Problem::Build(BuildError::BadPrimitive { .. }) => RkStatus::ErrBadTriangle,
        Problem::Build(BuildError::TooManyPrims { .. }) => RkStatus::ErrTooLarge,
        Problem::Build(BuildError::ArenaTooSmall { .. }) => RkStatus::ErrMemoryTooSmall,
        Problem::Build(_) | Problem::NotLinked | Problem::Length { .. } => RkStatus::ErrBadArgument,
    }
}

pub(super) fn failure_of(e: &SceneError, objects: &[RkObject]) -> Failure {
    let sphere = e.item == Item::Object
        && objects
            .get(e.index)
            .is_some_and(|o| o.shape == RK_SHAPE_SPHERES);
    // The kernel's item and field, renamed to the C struct and field holding the value.
    let (item, field) = match (e.item, e.field) {
        (Item::Object, "shape") => (RK_ITEM_OBJECT, "data"),
        (Item::Object, "material" | "motion") => (RK_ITEM_OBJECT, e.field),
        (Item::Object, _) => (RK_ITEM_SCENE, "memory"),
        (Item::Material, "albedo" | "reflectance" | "radiance") => (RK_ITEM_MATERIAL, "color"),
        (Item::Material, _) => (RK_ITEM_MATERIAL, e.field),
        (Item::Light, "lights") => (RK_ITEM_SCENE, "light_count"),
        (Item::Light, "corner" | "center") => (RK_ITEM_LIGHT, "position"),
        (Item::Light, "intensity" | "radiance") => (RK_ITEM_LIGHT, "color"),
        (Item::Light, _) => (RK_ITEM_LIGHT, e.field),
        (Item::Camera, _) => (RK_ITEM_CAMERA, e.field),
        (Item::Settings, "background") => (RK_ITEM_SCENE, "background"),
        (Item::Settings | Item::Tile, _) => (RK_ITEM_SETTINGS, e.field),
    };
    let mut f = Failure::new(status_of(e, sphere), item, e.index, field);
    if let Problem::OutOfRange { min, max } = e.problem {
        f.range = (min, max);
    }
    f
}
