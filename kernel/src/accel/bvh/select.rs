//! In-place, allocation-free, panic-free partitioning of primitive slots.

/// Reorders `ids` so those with `left(id)` come first; returns how many there are.
pub(super) fn partition<T: Copy>(ids: &mut [T], mut left: impl FnMut(&T) -> bool) -> usize {
    let mut i = 0;
    let mut j = ids.len();
    while i < j {
        if left(&ids[i]) {
            i += 1;
        } else {
            j -= 1;
            ids.swap(i, j);
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
        if budget == 0 {
            heapsort(&mut ids[lo..hi], &key);
            return;
        }
        budget -= 1;
        // Median of three as pivot, moved to the end.
        let mid = lo + (hi - lo) / 2;
        let (a, b, c) = (&ids[lo], &ids[mid], &ids[hi - 1]);
        let p = if less(&key, a, b) == less(&key, b, c) {
            mid
        } else if less(&key, b, a) == less(&key, a, c) {
            lo
        } else {
            hi - 1
        };
        ids.swap(p, hi - 1);
        let pivot = ids[hi - 1];
        let split = lo + partition(&mut ids[lo..hi - 1], |id| less(&key, id, &pivot));
        ids.swap(split, hi - 1);
        // ids[lo..split] < pivot = ids[split] < ids[split + 1..hi]
        if nth <= split {
            hi = split;
        } else {
            lo = split + 1;
        }
    }
}

fn heapsort<T: Copy>(v: &mut [T], key: &impl Fn(&T) -> (f32, u32)) {
    let sift = |v: &mut [T], mut root: usize, end: usize| loop {
        let mut child = 2 * root + 1;
        if child >= end {
            break;
        }
        if child + 1 < end && less(key, &v[child], &v[child + 1]) {
            child += 1;
        }
        if !less(key, &v[root], &v[child]) {
            break;
        }
        v.swap(root, child);
        root = child;
    };
    let n = v.len();
    for start in (0..n / 2).rev() {
        sift(v, start, n);
    }
    for end in (1..n).rev() {
        v.swap(0, end);
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
