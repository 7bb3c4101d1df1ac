//! Bounds on every resource a scene file, an input file or a command-line flag can request.
//!
//! Each is checked before anything is allocated or rendered, and each error names the real
//! limit (`width × height ≤ 67108864`), so a file can neither abort the process by asking for
//! more memory than there is nor keep it busy forever. The memory a render needs is estimated
//! from the same figures and compared with what the process may still use.

use raykernel::render::{Integrator, Settings};

/// Largest image, in pixels (`width × height`): 8192 × 8192.
pub const MAX_PIXELS: u64 = 1 << 26;
/// Largest width or height on its own (the product is bounded by [`MAX_PIXELS`]).
pub const MAX_SIDE: u32 = 1 << 16;
/// Most samples per pixel.
pub const MAX_SPP: u32 = 1 << 20;
/// Most reflection bounces.
pub const MAX_DEPTH: u32 = 64;
/// Longest path (segments) of the path integrator.
pub const MAX_PATH_LENGTH: u32 = 1024;
/// Most materials in a scene.
pub const MAX_MATERIALS: usize = 1 << 16;
/// Most objects in a scene.
pub const MAX_OBJECTS: usize = 1 << 20;
/// Most triangles in a scene (all meshes and inline triangles together) or in one OBJ file.
pub const MAX_TRIANGLES: usize = 1 << 26;
/// Most spheres in a scene.
pub const MAX_SPHERES: usize = 1 << 24;
/// Largest scene file (`.json`), bytes.
pub const MAX_SCENE_FILE_BYTES: u64 = 256 << 20;
/// Largest OBJ file, bytes.
pub const MAX_OBJ_FILE_BYTES: u64 = 2 << 30;
/// Largest `.camera` file, bytes.
pub const MAX_CAMERA_FILE_BYTES: u64 = 64 << 10;
/// Largest ray or hit file, bytes.
pub const MAX_RAY_FILE_BYTES: u64 = 8 << 30;

/// Bytes a render holds per pixel: the tiles' linear buffers and the assembled linear frame
/// (12 bytes each), the sRGB image and its PNG encoding (3 bytes each, the encoding at worst).
pub const RENDER_BYTES_PER_PIXEL: u64 = 12 + 12 + 3 + 3;
/// Extra bytes per pixel when the linear image is also written (its PFM encoding).
pub const LINEAR_BYTES_PER_PIXEL: u64 = 12;
/// Bytes a render holds per triangle, an upper estimate: the host's copy, the kernel's
/// converted triangle, its accelerator's share of nodes and ids.
pub const RENDER_BYTES_PER_TRIANGLE: u64 = 36 + 36 + 128;
/// Bytes a render holds per sphere, an upper estimate (as for triangles).
pub const RENDER_BYTES_PER_SPHERE: u64 = 16 + 16 + 128;

/// A request beyond a bound: the setting (as a scene file names it) and the message.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OverLimit {
    /// The field, e.g. `settings.spp`.
    pub field: &'static str,
    /// What was asked and what the limit is.
    pub msg: String,
}

fn over(field: &'static str, msg: String) -> Result<(), OverLimit> {
    Err(OverLimit { field, msg })
}

/// Checks render settings against [`MAX_PIXELS`], [`MAX_SIDE`], [`MAX_SPP`] and
/// [`MAX_DEPTH`] (zero sizes and zero samples are the kernel's to report).
///
/// # Errors
/// The first setting beyond its bound.
pub fn check_settings(s: &Settings) -> Result<(), OverLimit> {
    for (field, side) in [("settings.width", s.width), ("settings.height", s.height)] {
        if side > MAX_SIDE {
            return over(
                field,
                format!("{side} is more than the limit of {MAX_SIDE} pixels"),
            );
        }
    }
    let pixels = u64::from(s.width) * u64::from(s.height);
    if pixels > MAX_PIXELS {
        return over(
            "settings",
            format!(
                "{} × {} = {pixels} pixels; the limit is width × height ≤ {MAX_PIXELS} \
                 (8192 × 8192)",
                s.width, s.height
            ),
        );
    }
    if s.spp > MAX_SPP {
        return over(
            "settings.spp",
            format!("{} samples per pixel; the limit is {MAX_SPP}", s.spp),
        );
    }
    if s.max_depth > MAX_DEPTH {
        return over(
            "settings.max_depth",
            format!("{} bounces; the limit is {MAX_DEPTH}", s.max_depth),
        );
    }
    if let Integrator::Path { max_length } = s.integrator {
        if max_length > MAX_PATH_LENGTH {
            return over(
                "settings.max_path_length",
                format!("{max_length} segments; the limit is {MAX_PATH_LENGTH}"),
            );
        }
    }
    Ok(())
}

/// Checks a count of `what` (materials, objects, ...) against its bound.
///
/// # Errors
/// [`OverLimit`] at `field` if `count > max`.
pub fn check_count(
    field: &'static str,
    what: &str,
    count: usize,
    max: usize,
) -> Result<(), OverLimit> {
    if count > max {
        return over(field, format!("{count} {what}; the limit is {max}"));
    }
    Ok(())
}

/// Estimated peak bytes of rendering `triangles` and `spheres` at `settings` (see the
/// `RENDER_BYTES_*` constants).
#[must_use]
pub fn render_bytes(s: &Settings, triangles: usize, spheres: usize, linear: bool) -> u64 {
    let pixels = u64::from(s.width) * u64::from(s.height);
    let per_pixel = RENDER_BYTES_PER_PIXEL + if linear { LINEAR_BYTES_PER_PIXEL } else { 0 };
    pixels
        .saturating_mul(per_pixel)
        .saturating_add((triangles as u64).saturating_mul(RENDER_BYTES_PER_TRIANGLE))
        .saturating_add((spheres as u64).saturating_mul(RENDER_BYTES_PER_SPHERE))
}

/// Checks that `needed` bytes fit in what the process may still allocate
/// ([`available_bytes`]); passes when that is unknown.
///
/// # Errors
/// [`OverLimit`] at `settings`, stating both figures.
pub fn check_memory(needed: u64) -> Result<(), OverLimit> {
    match available_bytes() {
        Some(available) if needed > available => over(
            "settings",
            format!(
                "the render needs about {} of memory (image, geometry and accelerators), \
                 but only {} is available",
                human_bytes(needed),
                human_bytes(available)
            ),
        ),
        _ => Ok(()),
    }
}

/// Bytes the process may still allocate: the least of the system's available memory, the
/// cgroup's remaining allowance and the address-space limit less what is mapped already.
/// `None` where none of these can be read (not Linux).
#[must_use]
pub fn available_bytes() -> Option<u64> {
    let read = |p: &str| std::fs::read_to_string(p).ok();
    let kib_field = |text: &str, key: &str| -> Option<u64> {
        let line = text.lines().find(|l| l.starts_with(key))?;
        let kib: u64 = line[key.len()..].split_whitespace().next()?.parse().ok()?;
        Some(kib.saturating_mul(1024))
    };
    let system = read("/proc/meminfo").and_then(|t| kib_field(&t, "MemAvailable:"));
    let cgroup = (|| {
        let max: u64 = read("/sys/fs/cgroup/memory.max")?.trim().parse().ok()?;
        let current: u64 = read("/sys/fs/cgroup/memory.current")?.trim().parse().ok()?;
        Some(max.saturating_sub(current))
    })();
    let address_space = (|| {
        let limits = read("/proc/self/limits")?;
        let line = limits
            .lines()
            .find(|l| l.starts_with("Max address space"))?;
        let soft: u64 = line["Max address space".len()..]
            .split_whitespace()
            .next()?
            .parse()
            .ok()?;
        let mapped = read("/proc/self/status").and_then(|t| kib_field(&t, "VmSize:"))?;
        Some(soft.saturating_sub(mapped))
    })();
    [system, cgroup, address_space].into_iter().flatten().min()
}

/// `1.5 GiB`, `12.0 MiB`, `512 bytes`.
#[must_use]
pub fn human_bytes(n: u64) -> String {
    const UNITS: [(&str, u64); 3] = [("GiB", 1 << 30), ("MiB", 1 << 20), ("KiB", 1 << 10)];
    for (name, size) in UNITS {
        if n >= size {
            return format!("{:.1} {name}", n as f64 / size as f64);
        }
    }
    format!("{n} bytes")
}

#[cfg(test)]
mod tests {
    use super::*;
    use raykernel::render::scenes;

    fn settings(width: u32, height: u32, spp: u32, max_depth: u32) -> Settings {
        Settings {
            width,
            height,
            spp,
            max_depth,
            ..scenes::CORNELL.settings
        }
    }

    #[test]
    fn each_setting_is_bounded_and_the_message_names_the_limit() {
        assert_eq!(
            check_settings(&settings(8192, 8192, MAX_SPP, MAX_DEPTH)),
            Ok(())
        );
        let e = check_settings(&settings(u32::MAX, 1, 1, 0)).unwrap_err();
        assert_eq!(e.field, "settings.width");
        let e = check_settings(&settings(40000, 40000, 1, 0)).unwrap_err();
        assert_eq!(e.field, "settings");
        let e = check_settings(&settings(16384, 16384, 1, 0)).unwrap_err();
        assert_eq!(e.field, "settings");
        assert!(e.msg.contains("width × height ≤ 67108864"), "{}", e.msg);
        let e = check_settings(&settings(8, 8, u32::MAX, 0)).unwrap_err();
        assert_eq!(e.field, "settings.spp");
        let e = check_settings(&settings(8, 8, 1, u32::MAX)).unwrap_err();
        assert_eq!(e.field, "settings.max_depth");
        assert!(e.msg.contains("the limit is 64"), "{}", e.msg);
    }

    #[test]
    fn memory_estimate_grows_with_pixels_and_geometry() {
        let s = settings(100, 10, 1, 0);
        assert_eq!(render_bytes(&s, 0, 0, false), 1000 * RENDER_BYTES_PER_PIXEL);
        assert_eq!(
            render_bytes(&s, 2, 1, true),
            1000 * (RENDER_BYTES_PER_PIXEL + LINEAR_BYTES_PER_PIXEL)
                + 2 * RENDER_BYTES_PER_TRIANGLE
                + RENDER_BYTES_PER_SPHERE
        );
        assert!(check_memory(u64::MAX).is_err() || available_bytes().is_none());
        assert_eq!(check_memory(0), Ok(()));
    }

    #[test]
    fn byte_counts_read_as_units() {
        assert_eq!(human_bytes(512), "512 bytes");
        assert_eq!(human_bytes(3 << 19), "1.5 MiB");
        assert_eq!(human_bytes(MAX_SCENE_FILE_BYTES), "256.0 MiB");
    }
}
