//! Shared by the bare-metal programs: the golden cases (the same file the host test and the
//! Cortex-M suite compile), the golden table (the same file every target reads), the
//! instruction counter of each core, exit codes and the panic handler.
#![no_std]

pub use raykernel_testkit::golden as cases;
pub mod counter;
pub mod known_answers;
pub mod speed;

/// `tests/golden/kernel_hashes.txt`, embedded at build time.
pub const GOLDEN: &str = include_str!("../../golden/kernel_hashes.txt");

/// The expected hash of golden case `name`, if the file lists it (`None` too if the file is
/// malformed).
pub fn golden(name: &str) -> Option<u64> {
    let mut found = None;
    cases::parse_golden(GOLDEN, |n, v| {
        if n == name {
            found = Some(v);
        }
    })
    .ok()?;
    found
}

/// Ends the program: QEMU exits with `code` (semihosting).
pub fn exit(code: i32) -> ! {
    semihosting::process::exit(code)
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo<'_>) -> ! {
    semihosting::eprintln!("panicked: {}", info);
    exit(101)
}

/// The Cortex-M default HardFault handler spins, so QEMU would hang until the runner's
/// timeout: exit instead.
#[cfg(target_arch = "arm")]
#[cortex_m_rt::exception]
unsafe fn HardFault(_: &cortex_m_rt::ExceptionFrame) -> ! {
    exit(102)
}
