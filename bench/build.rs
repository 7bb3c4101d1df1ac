//! Records the compiler that builds the benchmark, for the report's machine line; with the
//! `embree` feature, compiles the Embree shim (C) and links the system's libembree3; with the
//! `tinybvh` feature, compiles the shim over tinybvh's 8-wide CPU BVH (C++) from the header
//! the `tinybvh-rs` crate ships.
use std::path::{Path, PathBuf};
use std::process::Command;

/// The `tinybvh-rs` release whose `tiny_bvh.h` the shim compiles (`Cargo.toml` pins it).
const TINYBVH_RS: &str = "tinybvh-rs-0.1.0-beta.3";

fn main() {
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let version = Command::new(rustc)
        .arg("--version")
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .unwrap_or_else(|| "rustc (unknown version)".into());
    println!("cargo:rustc-env=HOST_RUSTC_VERSION={}", version.trim());
    println!("cargo:rerun-if-env-changed=RUSTC");
    println!("cargo:rerun-if-changed=build.rs");
    if std::env::var_os("CARGO_FEATURE_EMBREE").is_some() {
        println!("cargo:rerun-if-changed=csrc/embree_shim.c");
        cc::Build::new()
            .file("csrc/embree_shim.c")
            .warnings(true)
            .compile("rkb_embree_shim");
        println!("cargo:rustc-link-lib=embree3");
    }
    if std::env::var_os("CARGO_FEATURE_TINYBVH").is_some() {
        println!("cargo:rerun-if-changed=csrc/tinybvh8_shim.cpp");
        let include = tinybvh_header_dir().unwrap_or_else(|| {
            panic!(
                "feature `tinybvh`: no {TINYBVH_RS}/ffi/tinybvh/tiny_bvh.h under the cargo \
                 registry ($CARGO_HOME/registry/src); fetch the crate with `cargo fetch`"
            )
        });
        // The flags tinybvh-rs builds the same header with; tinybvh's own warnings are not ours.
        cc::Build::new()
            .cpp(true)
            .std("c++20")
            .flag("-march=native")
            .include(include)
            .file("csrc/tinybvh8_shim.cpp")
            .warnings(false)
            .compile("rkb_tinybvh8_shim");
    }
}

/// The directory holding `tiny_bvh.h` in the registry copy of [`TINYBVH_RS`].
fn tinybvh_header_dir() -> Option<PathBuf> {
    let home = std::env::var_os("CARGO_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| Path::new(&h).join(".cargo")))?;
    let registries = std::fs::read_dir(home.join("registry").join("src")).ok()?;
    registries
        .flatten()
        .map(|r| r.path().join(TINYBVH_RS).join("ffi").join("tinybvh"))
        .find(|dir| dir.join("tiny_bvh.h").is_file())
}
