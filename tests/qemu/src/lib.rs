//! Shared by the on-target tests and bins: the golden cases (the same file the host test
//! compiles) and the golden table generated from `tests/golden/kernel_hashes.txt` by build.rs.
#![no_std]

pub use raykernel_testkit::golden as cases;

/// The golden table.
pub mod golden {
    include!(concat!(env!("OUT_DIR"), "/golden.rs"));

    /// The expected hash of case `name`, if the file lists it.
    pub fn expected(name: &str) -> Option<u64> {
        GOLDEN.iter().find(|(n, _)| *n == name).map(|&(_, v)| v)
    }
}

use cases::Fail;
use raykernel::bvh::{InvalidTree, Sah, StaticBuild, TreeStats};
use raykernel::render::scenes::SceneData;
use raykernel::render::AllFeatures;
use raykernel::{Accel, Bvh4, Bvh8, BvhFamily, Primitive, Scalar};

/// RAM of the machine the tests run on, as build.rs sizes memory.x: 16 KB on the M0's
/// micro:bit, 64 KB on the LM3S6965 (M3) and the MPS2 (M4F).
pub const RAM_BYTES: usize = include!(concat!(env!("OUT_DIR"), "/ram.rs"));

/// A wide BVH of either width, so on-target code is written once over the width
/// (`WideBvh<'_, S, P, W>` with `W` = 4 or 8): the kernel writes `validate` per width (each
/// with its traversal's stack bound), and this trait reaches it.
pub trait WideTree<S: Scalar>: Accel<S> {
    /// `Bvh4::validate` or `Bvh8::validate`.
    fn check(&self) -> Result<TreeStats, InvalidTree>;
}

impl<S: Scalar, P: Primitive<S>> WideTree<S> for Bvh4<'_, S, P> {
    fn check(&self) -> Result<TreeStats, InvalidTree> {
        self.validate()
    }
}

impl<S: Scalar, P: Primitive<S>> WideTree<S> for Bvh8<'_, S, P> {
    fn check(&self) -> Result<TreeStats, InvalidTree> {
        self.validate()
    }
}

/// A short description of a failed case.
pub fn fail_name(f: Fail) -> &'static str {
    match f {
        Fail::UnknownCase => "unknown case",
        Fail::Rejected { .. } => "kernel rejected generated input",
        Fail::Build => "build failed",
        Fail::Invalid => "validate() rejected the tree",
        Fail::Differs { .. } => "BVH differs from brute force",
        Fail::NotLinked => "needs a kernel feature this build leaves out (path-tracing)",
    }
}

/// Computes golden case `name` on target and compares with the host-generated table.
pub fn check_golden(name: &str) {
    check_golden_with(name, cases::compute)
}

/// The renderer's accelerators on target: a SAH BVH per object without the reinsertion pass
/// (the same images as every other family; the pass's frames would not fit the M0's 16 KB of
/// RAM beside a render's buffers, and the kernel suite checks its trees).
pub type RenderFamily = BvhFamily<StaticBuild<Sah, false>>;

/// Renders built-in scene `data` in mode `S` with [`RenderFamily`] and every part of the
/// renderer, and hashes it ([`cases::render_hash`]).
pub fn render_hash<S: cases::Bits + Scalar>(data: &SceneData<'_>) -> Result<u64, Fail> {
    cases::render_hash_with::<S, RenderFamily, AllFeatures>(data, StaticBuild::default())
}

/// As [`check_golden`] for the render case `name`: built-in scene `scene` in mode `S`.
pub fn check_render_golden<S: cases::Bits + Scalar>(name: &str, scene: &SceneData<'_>) {
    check_golden_with(name, |_| render_hash::<S>(scene))
}

fn check_golden_with(name: &str, compute: impl FnOnce(&str) -> Result<u64, Fail>) {
    let want = golden::expected(name);
    defmt::assert!(want.is_some(), "{} missing from kernel_hashes.txt", name);
    match compute(name) {
        Ok(got) => defmt::assert_eq!(
            got,
            want.unwrap_or(0),
            "golden {}: computed {=u64:#018x}, file {=u64:#018x}",
            name,
            got,
            want.unwrap_or(0)
        ),
        Err(e) => defmt::panic!("golden {}: {}", name, fail_name(e)),
    }
}

/// Stack painting: how much stack a piece of code uses, measured on target.
pub mod stack {
    /// The pattern free stack is painted with.
    const PAINT: u32 = 0xa5c3_5a3c;

    extern "C" {
        /// The linker's lowest stack address (cortex-m-rt); the stack grows down towards it.
        static _stack_end: u32;
        /// The top of the stack (end of RAM).
        static _stack_start: u32;
    }

    pub fn stack_bottom() -> usize {
        core::ptr::addr_of!(_stack_end) as usize
    }

    /// Fills the free stack from its end up to `top` with a pattern.
    #[inline(never)]
    pub fn paint(top: usize) {
        let mut p = stack_bottom();
        while p < top {
            // SAFETY: [stack end, top) is free stack below the caller's frame, word aligned.
            unsafe { core::ptr::write_volatile(p as *mut u32, PAINT) };
            p += 4;
        }
    }

    /// The lowest address at or below `top` whose paint was overwritten.
    #[inline(never)]
    pub fn lowest_used(top: usize) -> usize {
        let mut p = stack_bottom();
        // SAFETY: as in `paint`; reads only.
        while p < top && unsafe { core::ptr::read_volatile(p as *const u32) } == PAINT {
            p += 4;
        }
        defmt::assert!(p > stack_bottom(), "stack overflowed its painted region");
        p
    }

    /// Fills the free stack below the caller's frame with a pattern, runs `f`, and returns how
    /// many bytes below the painted top `f` used (found by scanning up from the stack's end).
    #[inline(never)]
    pub fn stack_use(f: impl FnOnce()) -> usize {
        const GAP: usize = 256; // left alone: this frame and the calls painting makes
        let top = cortex_m::register::msp::read() as usize - GAP;
        paint(top);
        f();
        top - lowest_used(top)
    }

    /// The top of the stack (the end of RAM).
    pub fn stack_top() -> usize {
        core::ptr::addr_of!(_stack_start) as usize
    }

    /// Logs how much of the stack the run used since [`paint`] (down from the end of RAM) and
    /// fails when less than 512 bytes of the target's RAM stayed free, before an overflow would.
    pub fn assert_headroom() {
        let top = stack_top();
        let low = lowest_used(top);
        let free = low - stack_bottom();
        defmt::info!(
            "stack peak of the run: {=usize} B used, {=usize} B free",
            top - low,
            free
        );
        defmt::assert!(free >= 512, "only {=usize} bytes of stack left", free);
    }
}
