//! Writes memory.x (from memory.x.in, RAM sized per target) on the linker path and turns the golden hash file into Rust source, so the
//! on-target tests compare with the same file the host test reads (no second copy).

use std::env;
use std::fmt::Write as _;
use std::fs;
use std::path::PathBuf;

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("OUT_DIR"));
    // memory.x.in says 16 KB of RAM, the micro:bit's own (the M0, QEMU's micro:bit machine);
    // the LM3S6965 and the MPS2 get 64 KB.
    // The same size is `raykernel_qemu::RAM_BYTES` (ram.rs), for tests that size scenes by it.
    let memory = fs::read_to_string("memory.x.in").expect("read memory.x.in");
    let ram_kb = if env::var("TARGET").is_ok_and(|t| t != "thumbv6m-none-eabi") {
        64
    } else {
        16
    };
    let memory = memory.replace("LENGTH = 16K", &format!("LENGTH = {ram_kb}K"));
    fs::write(out.join("memory.x"), memory).expect("write memory.x");
    fs::write(out.join("ram.rs"), format!("{}\n", ram_kb * 1024)).expect("write ram.rs");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=memory.x.in");

    let golden = "../golden/kernel_hashes.txt";
    println!("cargo:rerun-if-changed={golden}");
    let text = fs::read_to_string(golden).expect("read ../golden/kernel_hashes.txt");
    let mut src =
        String::from("/// `(name, hash)` from tests/golden/kernel_hashes.txt, in file order.\n");
    src.push_str("pub const GOLDEN: &[(&str, u64)] = &[\n");
    for (no, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let bad = || format!("{golden}:{}: expected `name = 0x<hex>`", no + 1);
        let (name, value) = line.split_once('=').unwrap_or_else(|| panic!("{}", bad()));
        let hex = value
            .trim()
            .strip_prefix("0x")
            .unwrap_or_else(|| panic!("{}", bad()));
        let v = u64::from_str_radix(hex, 16).unwrap_or_else(|_| panic!("{}", bad()));
        let name = name.trim();
        assert!(
            !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_'),
            "{}",
            bad()
        );
        writeln!(src, "    ({name:?}, {v:#018x}),").unwrap();
    }
    src.push_str("];\n");
    fs::write(out.join("golden.rs"), src).expect("write golden.rs");
}
