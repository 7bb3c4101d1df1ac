//! In-place, allocation-free, panic-free partitioning of primitive slots.

/// Swaps `v[a]` and `v[b]`; a no-op if either index is out of range or they are equal.
/// Callers pass proven indices: the checks only let the compiler drop a panic path. Through
/// two disjoint borrows rather than `slice::swap`, which may see one slot twice and so
/// calls `memmove` on thumb targets for 32-byte slots.
#[inline(always)]
pub(super) fn swap_in<T>(v: &mut [T], a: usize, b: usize) {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    if let Some((left, right)) = v.split_at_mut_checked(hi) {
        if let (Some(x), Some(y)) = (left.get_mut(lo), right.first_mut()) {
            core::mem::swap(x, y);
        }
    }
}

/// Reorders `ids` so those with `left(id)` come first; returns how many there are.
pub(super) fn partition<T: Copy>(ids: &mut [T], mut left: impl FnMut(&T) -> bool) -> usize {
    let mut i = 0;
    let mut j = ids.len();
    while i < j {
        let Some(id) = ids.get(i) else { break };
        if left(id) {
            i += 1;
        } else {
            j -= 1;
            swap_in(ids, i, j);
        }
    }
    i
}

/// The strict total order used for median splits: `key` gives (key, id), ids are distinct.
#[inline]
fn less<T>(key: &impl Fn(&T) -> (f32, u32), a: &T, b: &T) -> bool {
    let (ka, ia) = key(a);
    let (kb, ib) = key(b);
    ka < kb || (ka == kb && ia < ib)
}

/// Reorders `ids` so that the first `nth` are the `nth` smallest under (key, id).
/// Quickselect with a median-of-three pivot; after `2·log2(n)` rounds it falls back to
/// heapsort of what is left, so the worst case stays `O(n log n)`. Keys must not be NaN.
pub(super) fn select_nth<T: Copy>(ids: &mut [T], nth: usize, key: impl Fn(&T) -> (f32, u32)) {
    let (mut lo, mut hi) = (0usize, ids.len());
    let mut budget = 2 * (usize::BITS - ids.len().leading_zeros());
    while hi - lo > 1 && nth > lo && nth < hi {
        let Some(w) = ids.get_mut(lo..hi) else { return };
        if budget == 0 {
            heapsort(w, &key);
            return;
        }
        budget -= 1;
        // Median of three as pivot, moved to the end (indices relative to `w = ids[lo..hi]`).
        let (mid, last) = (w.len() / 2, w.len() - 1);
        let (Some(a), Some(b), Some(c)) = (w.first(), w.get(mid), w.get(last)) else {
            return;
        };
        let p = if less(&key, a, b) == less(&key, b, c) {
            mid
        } else if less(&key, b, a) == less(&key, a, c) {
            0
        } else {
            last
        };
        swap_in(w, p, last);
        let Some((pivot, rest)) = w.split_last_mut() else {
            return;
        };
        let pivot = *pivot;
        let split = partition(rest, |id| less(&key, id, &pivot));
        swap_in(w, split, last);
        // w[..split] < pivot = w[split] < w[split + 1..]
        let split = lo + split;
        if nth <= split {
            hi = split;
        } else {
            lo = split + 1;
        }
    }
}

fn heapsort<T: Copy>(v: &mut [T], key: &impl Fn(&T) -> (f32, u32)) {
    let sift = |v: &mut [T], mut root: usize, end: usize| {
        let end = end.min(v.len());
        loop {
            let mut child = 2 * root + 1;
            if child >= end {
                break;
            }
            if let (Some(a), Some(b)) = (v.get(child), v.get(child + 1)) {
                if child + 1 < end && less(key, a, b) {
                    child += 1;
                }
            }
            let (Some(r), Some(c)) = (v.get(root), v.get(child)) else {
                break;
            };
            if !less(key, r, c) {
                break;
            }
            swap_in(v, root, child);
            root = child;
        }
    };
    let n = v.len();
    for start in (0..n / 2).rev() {
        sift(v, start, n);
    }
    for end in (1..n).rev() {
        swap_in(v, 0, end);
        sift(v, 0, end);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn select_nth_splits_by_key_then_id() {
        let keys = [5.0f32, 1.0, 3.0, 3.0, 9.0, 0.0, 3.0, 7.0];
        for nth in 0..=keys.len() {
            let mut ids: [u32; 8] = core::array::from_fn(|i| i as u32);
            select_nth(&mut ids, nth, |&i| (keys[i as usize], i));
            let mut sorted: [u32; 8] = core::array::from_fn(|i| i as u32);
            sorted.sort_by(|&a, &b| {
                keys[a as usize]
                    .total_cmp(&keys[b as usize])
                    .then(a.cmp(&b))
            });
            let mut left = ids[..nth].to_vec();
            left.sort_unstable();
            let mut want = sorted[..nth].to_vec();
            want.sort_unstable();
            assert_eq!(left, want, "nth = {nth}");
        }
    }

    #[test]
    fn heapsort_sorts() {
        let keys = [4.0f32, 4.0, 2.0, 8.0, 1.0];
        let mut ids = [0u32, 1, 2, 3, 4];
        heapsort(&mut ids, &|&i| (keys[i as usize], i));
        assert_eq!(ids, [4, 2, 0, 1, 3]);
    }
}
