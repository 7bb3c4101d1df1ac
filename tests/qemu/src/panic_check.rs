//! The panic handler of the panic-freedom images (`panic_never*`), included by each with
//! `#[path]`: it calls a function nobody defines, so any panic path left after optimisation
//! fails the link.

/// With feature `list-panics` the handler spins instead, so the binary links and
/// `cargo xtask panic-check` can list the functions that still call into the panic machinery.
#[cfg(feature = "list-panics")]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {
        cortex_m::asm::nop();
    }
}

#[cfg(not(feature = "list-panics"))]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    extern "C" {
        fn kernel_has_a_reachable_panic_path() -> !;
    }
    // SAFETY: never defined; any call that survives optimisation fails the link, on purpose.
    unsafe { kernel_has_a_reachable_panic_path() }
}
