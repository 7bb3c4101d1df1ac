//! Test support shared by every raykernel suite, host and on-target alike: the seeded generator
//! ([`Rng`]), the icosahedron meshes ([`icosphere`]), `f64` vector helpers ([`vec3`]) and the
//! golden cases ([`golden`]), and (with `std`) owned accelerator memory (`memory`).
//!
//! `no_std` and allocation-free by default, so the QEMU and bare-metal suites link it; the `std`
//! feature adds what allocates or needs the platform's `f64` functions. A dev-dependency only:
//! no shipped crate depends on it.
#![no_std]

#[cfg(feature = "std")]
extern crate std;

pub mod golden;
pub mod icosphere;
#[cfg(feature = "std")]
pub mod memory;
pub mod rng;
pub mod vec3;

pub use rng::Rng;

/// `dir`, created empty: whatever an earlier run left there (a test directory named by a
/// process id can come back in a later run) is removed first.
///
/// # Panics
/// If the directory cannot be created.
#[cfg(feature = "std")]
#[must_use]
pub fn empty_dir(dir: std::path::PathBuf) -> std::path::PathBuf {
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}
