//! Buffers for large acceleration structures, asked to be backed by huge pages.
//!
//! A walk through a tree of tens of megabytes lands on a different 4 KiB page at almost every
//! node, so most node loads also miss the TLB. Linux backs an anonymous range with 2 MiB pages
//! (transparent huge pages) when the process asks for it with `madvise(MADV_HUGEPAGE)` before
//! first touching the range, which in its default `madvise` mode is the only way to get them;
//! Embree asks so for its BVH. The host asks so for the node arenas and the leaf-order
//! triangles ([`filled`], [`copied`]); elsewhere, and for buffers under one huge page, these
//! are plain vectors.

/// The huge page size asked for (x86-64 and most aarch64 Linux kernels).
#[cfg_attr(not(target_os = "linux"), allow(dead_code))]
const HUGE_PAGE: usize = 2 << 20;

/// `len` copies of `value`, in a buffer asked for huge pages if it spans one.
#[must_use]
pub fn filled<T: Clone>(len: usize, value: T) -> Vec<T> {
    let mut v = advised(len);
    v.resize(len, value);
    v
}

/// A copy of `xs`, in a buffer asked for huge pages if it spans one.
#[must_use]
pub fn copied<T: Clone>(xs: &[T]) -> Vec<T> {
    let mut v = advised(xs.len());
    v.extend_from_slice(xs);
    v
}

/// An empty vector with room for `len` values, its buffer advised before anything touches it.
fn advised<T>(len: usize) -> Vec<T> {
    let v = Vec::with_capacity(len);
    advise_huge_pages(&v);
    v
}

/// Asks Linux to back the whole pages of `v`'s allocation with huge pages, if it spans one.
/// Advice only: the contents, and what the program may do with them, are unchanged, and a
/// kernel without transparent huge pages (or with them disabled) ignores it.
#[cfg(target_os = "linux")]
#[allow(unsafe_code)]
fn advise_huge_pages<T>(v: &Vec<T>) {
    const PAGE: usize = 4096;
    let bytes = v.capacity().saturating_mul(size_of::<T>());
    if bytes < HUGE_PAGE {
        return;
    }
    let base = v.as_ptr() as usize;
    let start = base.next_multiple_of(PAGE);
    let end = (base + bytes) / PAGE * PAGE;
    if end > start {
        // SAFETY: `[start, end)` is whole pages inside `v`'s allocation, which this process
        // owns; `MADV_HUGEPAGE` changes how the kernel backs them, never their contents or
        // validity. A failure (e.g. another page size) leaves them as they were and is ignored.
        let _ =
            unsafe { libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE) };
    }
}

#[cfg(not(target_os = "linux"))]
fn advise_huge_pages<T>(_v: &Vec<T>) {}

#[cfg(test)]
mod tests {
    use super::{copied, filled, HUGE_PAGE};

    /// Kilobytes of huge pages in the mapping that holds `addr`, from `/proc/self/smaps`.
    #[cfg(target_os = "linux")]
    fn huge_kb_at(addr: usize) -> Option<u64> {
        let smaps = std::fs::read_to_string("/proc/self/smaps").ok()?;
        let mut inside = false;
        for line in smaps.lines() {
            let range = line
                .split_whitespace()
                .next()
                .and_then(|r| r.split_once('-'));
            if let Some((lo, hi)) = range.filter(|_| !line.starts_with(char::is_uppercase)) {
                let parse = |x: &str| usize::from_str_radix(x, 16).ok();
                inside =
                    matches!((parse(lo), parse(hi)), (Some(l), Some(h)) if l <= addr && addr < h);
            } else if inside {
                if let Some(kb) = line.strip_prefix("AnonHugePages:") {
                    return kb.trim().trim_end_matches("kB").trim().parse().ok();
                }
            }
        }
        None
    }

    /// Where the kernel offers transparent huge pages on request, a large buffer gets some.
    /// (64 MiB: above glibc's largest threshold for serving a request from fresh mapped pages.)
    #[cfg(target_os = "linux")]
    #[test]
    fn a_large_buffer_is_backed_by_huge_pages_where_offered() {
        let mode = std::fs::read_to_string("/sys/kernel/mm/transparent_hugepage/enabled");
        let Ok(mode) = mode else {
            eprintln!("skipped: this kernel has no transparent huge pages");
            return;
        };
        if mode.contains("[never]") {
            eprintln!(
                "skipped: transparent huge pages are disabled here ({})",
                mode.trim()
            );
            return;
        }
        let v = filled(64 << 20, 1u8);
        let huge = huge_kb_at(v.as_ptr() as usize + v.len() / 2);
        assert!(
            huge.is_some_and(|kb| kb >= 2048),
            "{huge:?} kB of huge pages ({})",
            mode.trim()
        );
    }

    #[test]
    fn buffers_hold_what_was_asked_for_large_and_small() {
        for len in [0, 3, HUGE_PAGE / 4 + 5] {
            let v = filled(len, 7u32);
            assert_eq!(v.len(), len);
            assert!(v.iter().all(|&x| x == 7));
            let xs: Vec<u32> = (0..len as u32).collect();
            assert_eq!(copied(&xs), xs);
        }
    }
}
