//! Writes the linker's memory map for the target into OUT_DIR: RAM only on RISC-V (QEMU's
//! `virt` loads the ELF into its DRAM at 0x8000_0000), flash and RAM on the Cortex-M machines
//! (as tests/qemu: 32 KB of RAM on the M0's micro:bit, 64 KB on the others).

use std::env;
use std::fs;
use std::path::PathBuf;

const RISCV: &str = "MEMORY
{
  RAM : ORIGIN = 0x80000000, LENGTH = 16M
}
REGION_ALIAS(\"REGION_TEXT\", RAM);
REGION_ALIAS(\"REGION_RODATA\", RAM);
REGION_ALIAS(\"REGION_DATA\", RAM);
REGION_ALIAS(\"REGION_BSS\", RAM);
REGION_ALIAS(\"REGION_HEAP\", RAM);
REGION_ALIAS(\"REGION_STACK\", RAM);
";

fn cortex_m(ram_kb: u32) -> String {
    format!(
        "MEMORY\n{{\n  FLASH : ORIGIN = 0x00000000, LENGTH = 256K\n  RAM   : ORIGIN = 0x20000000, LENGTH = {ram_kb}K\n}}\n"
    )
}

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("OUT_DIR"));
    let target = env::var("TARGET").unwrap_or_default();
    let memory = if target.starts_with("riscv32") {
        RISCV.to_string()
    } else if target == "thumbv6m-none-eabi" {
        cortex_m(32)
    } else {
        cortex_m(64)
    };
    fs::write(out.join("memory.x"), memory).expect("write memory.x");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=../golden/kernel_hashes.txt");
}
