//! Records the compiler that builds the benchmark, for the report's machine line; with the
//! `embree` feature, compiles the Embree shim (C) and links the system's libembree3.
use std::process::Command;

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
}
