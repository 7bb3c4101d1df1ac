//! Buffers for the memory the kernel is handed, backed by huge pages where the OS offers them.
//!
//! Traversal reads nodes and triangles scattered over the whole structure: for a scene of a
//! million triangles that is tens of megabytes, and with 4 KiB pages most of those reads also
//! miss the TLB. On Linux, every buffer made here that spans at least one whole [`HUGE_PAGE`]
//! is advised `MADV_HUGEPAGE` before it is first written, so that the kernel backs its aligned
//! 2 MiB stretches with huge pages where it can (transparent huge pages set to `madvise` or
//! `always`). Elsewhere, or where the advice is refused, the buffer is an ordinary one: only
//! speed depends on it, never contents.

/// The huge-page size advised for (x86_64 and most aarch64 Linux kernels): only whole, aligned
/// stretches of it can be backed by a huge page.
pub const HUGE_PAGE: usize = 2 << 20;

/// `len` clones of `value`.
#[must_use]
pub fn filled<T: Clone>(len: usize, value: T) -> Vec<T> {
    let mut v = Vec::with_capacity(len);
    advise_huge_pages(&v);
    v.resize(len, value);
    v
}

/// A copy of `items`.
#[must_use]
pub fn copied<T: Clone>(items: &[T]) -> Vec<T> {
    let mut v = Vec::with_capacity(items.len());
    advise_huge_pages(&v);
    v.extend_from_slice(items);
    v
}

/// The items of `iter` (at most `len`, the expected count), or its first error.
///
/// # Errors
/// The first error `iter` yields.
pub fn collected<T, E>(len: usize, iter: impl Iterator<Item = Result<T, E>>) -> Result<Vec<T>, E> {
    let mut v = Vec::with_capacity(len);
    advise_huge_pages(&v);
    for item in iter {
        v.push(item?);
    }
    Ok(v)
}

/// The aligned [`HUGE_PAGE`] stretches inside `v`'s capacity, as an address range (empty if
/// there is none).
fn huge_stretches<T>(v: &Vec<T>) -> core::ops::Range<usize> {
    let start = v.as_ptr() as usize;
    let end = start.saturating_add(v.capacity().saturating_mul(size_of::<T>()));
    let lo = start.div_ceil(HUGE_PAGE).saturating_mul(HUGE_PAGE);
    let hi = end / HUGE_PAGE * HUGE_PAGE;
    lo..hi.max(lo)
}

/// Advises the huge-page stretches of `v`'s capacity `MADV_HUGEPAGE` (Linux; a no-op
/// elsewhere). Call before the first write: pages already touched keep their size.
#[allow(unsafe_code)]
fn advise_huge_pages<T>(v: &Vec<T>) {
    let range = huge_stretches(v);
    if range.is_empty() {
        return;
    }
    #[cfg(target_os = "linux")]
    // SAFETY: `range` lies inside the allocation `v` owns (its capacity) and is page-aligned
    // (2 MiB is a multiple of every base page size Linux uses). `MADV_HUGEPAGE` only changes how
    // the kernel backs those pages, never their contents, so no reference to them is affected.
    // A refusal (kernel without transparent huge pages) is harmless and ignored.
    unsafe {
        libc::madvise(
            range.start as *mut libc::c_void,
            range.len(),
            libc::MADV_HUGEPAGE,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn contents_are_what_was_asked_for() {
        let big = HUGE_PAGE / 4 * 3; // three huge pages of u32
        assert_eq!(filled(big, 7u32), vec![7u32; big]);
        let items: Vec<u32> = (0..big as u32).collect();
        assert_eq!(copied(&items), items);
        let ok: Result<Vec<u32>, ()> = collected(big, items.iter().map(|&x| Ok(x)));
        assert_eq!(ok.unwrap(), items);
        let failed = collected(3, [Ok(1u8), Err("second"), Ok(3)].into_iter());
        assert_eq!(failed, Err("second"));
        assert!(filled(0, 1u8).is_empty());
    }

    #[test]
    fn stretches_are_whole_aligned_huge_pages_inside_the_buffer() {
        let v: Vec<u8> = Vec::with_capacity(3 * HUGE_PAGE);
        let r = huge_stretches(&v);
        let (start, end) = (v.as_ptr() as usize, v.as_ptr() as usize + 3 * HUGE_PAGE);
        assert!(
            r.start >= start && r.end <= end,
            "{r:x?} outside {start:x}..{end:x}"
        );
        assert_eq!(r.start % HUGE_PAGE, 0);
        assert_eq!(r.end % HUGE_PAGE, 0);
        assert!(r.len() >= 2 * HUGE_PAGE, "{r:x?}");
        let small: Vec<u8> = Vec::with_capacity(HUGE_PAGE / 2);
        assert!(huge_stretches(&small).is_empty());
    }

    /// The advice reaches the kernel: the mapping holding the buffer's huge-page stretch is
    /// flagged `hg` in `/proc/self/smaps`. Skipped (with a note) on a kernel without
    /// transparent huge pages.
    #[cfg(target_os = "linux")]
    #[test]
    fn large_buffers_are_advised_huge_pages() {
        if !std::path::Path::new("/sys/kernel/mm/transparent_hugepage/enabled").exists() {
            eprintln!("skipped: this kernel has no transparent huge pages");
            return;
        }
        let v = filled(4 * HUGE_PAGE, 1u8);
        let r = huge_stretches(&v);
        let smaps = std::fs::read_to_string("/proc/self/smaps").expect("/proc/self/smaps");
        let mut inside = false;
        let mut flags = None;
        for line in smaps.lines() {
            if let Some((span, _)) = line.split_once(' ') {
                if let Some((a, b)) = span.split_once('-') {
                    if let (Ok(a), Ok(b)) =
                        (usize::from_str_radix(a, 16), usize::from_str_radix(b, 16))
                    {
                        inside = a <= r.start && r.start < b;
                        continue;
                    }
                }
            }
            if inside {
                if let Some(f) = line.strip_prefix("VmFlags:") {
                    flags = Some(f.to_string());
                }
            }
        }
        let flags = flags.expect("a mapping holds the buffer");
        assert!(
            flags.split_whitespace().any(|f| f == "hg"),
            "VmFlags:{flags}"
        );
    }
}
