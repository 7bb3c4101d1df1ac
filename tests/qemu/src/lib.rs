//! Shared by the on-target tests and bins: the golden cases (the same file the host test
//! compiles) and the golden table generated from `tests/golden/kernel_hashes.txt` by build.rs.
#![no_std]

#[path = "../../golden/cases.rs"]
pub mod cases;

/// The golden table.
pub mod golden {
    include!(concat!(env!("OUT_DIR"), "/golden.rs"));

    /// The expected hash of case `name`, if the file lists it.
    pub fn expected(name: &str) -> Option<u64> {
        GOLDEN.iter().find(|(n, _)| *n == name).map(|&(_, v)| v)
    }
}
