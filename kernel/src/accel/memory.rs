//! The caller's memory for accelerators, and how much of it a build takes.

use super::bvh::{nodes_needed, Node};
use super::grid::GridSize;
use super::kdtree::{self, KdNode};
use super::wide::{collapse_words_needed, nodes4_needed, nodes8_needed, Node4, Node8};
use crate::scalar::Scalar;

/// Memory for accelerator builds: one buffer per element type. A build takes its share from
/// the front of each buffer and leaves the rest, so one value serves a sequence of builds
/// (the renderer builds every object into one). Longer buffers than needed are fine.
#[derive(Debug)]
pub struct AccelMemory<'a, S: Scalar> {
    /// Binary BVH nodes (the 4-wide BVH's build takes them too, as scratch).
    pub nodes: &'a mut [Node<S>],
    /// 4-wide BVH nodes.
    pub nodes4: &'a mut [Node4<S>],
    /// 8-wide BVH nodes.
    pub nodes8: &'a mut [Node8<S>],
    /// Kd-tree nodes.
    pub kd_nodes: &'a mut [KdNode<S>],
    /// Index words: BVH primitive ids, grid cell offsets and references, kd-tree references,
    /// and the wide BVHs' collapse scratch.
    pub words: &'a mut [u32],
}

impl<S: Scalar> Default for AccelMemory<'_, S> {
    /// No memory at all: enough for brute force and for empty inputs.
    fn default() -> Self {
        Self {
            nodes: &mut [],
            nodes4: &mut [],
            nodes8: &mut [],
            kd_nodes: &mut [],
            words: &mut [],
        }
    }
}

/// Takes the first `n` slots of a buffer (all of them if it is shorter), leaving the rest.
pub(crate) fn take<'a, T>(buf: &mut &'a mut [T], n: usize) -> &'a mut [T] {
    let all = core::mem::take(buf);
    let n = n.min(all.len());
    let (mine, rest) = all.split_at_mut(n);
    *buf = rest;
    mine
}

impl<S: Scalar> AccelMemory<'_, S> {
    /// The buffers' lengths, in the form [`MemoryNeeded`] states requirements.
    #[must_use]
    pub fn available(&self) -> MemoryNeeded {
        MemoryNeeded {
            nodes: self.nodes.len(),
            nodes4: self.nodes4.len(),
            nodes8: self.nodes8.len(),
            kd_nodes: self.kd_nodes.len(),
            words: self.words.len(),
        }
    }
}

/// Buffer lengths (elements, not bytes) of an [`AccelMemory`] that a build takes, exact:
/// from [`crate::AccelKind::memory_needed`] or, when the count alone decides,
/// [`crate::AccelKind::memory_for_count`] in `const` context.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MemoryNeeded {
    /// Length of [`AccelMemory::nodes`].
    pub nodes: usize,
    /// Length of [`AccelMemory::nodes4`].
    pub nodes4: usize,
    /// Length of [`AccelMemory::nodes8`].
    pub nodes8: usize,
    /// Length of [`AccelMemory::kd_nodes`].
    pub kd_nodes: usize,
    /// Length of [`AccelMemory::words`].
    pub words: usize,
}

/// A buffer shorter than required, as [`MemoryNeeded::first_shortfall`] finds it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shortfall {
    /// The [`MemoryNeeded`] field naming the buffer: `nodes`, `nodes4`, `nodes8`, `kd_nodes`
    /// or `words`.
    pub field: &'static str,
    /// Length required.
    pub needed: usize,
    /// Length available.
    pub available: usize,
}

impl MemoryNeeded {
    /// Nothing.
    pub const NONE: Self = Self {
        nodes: 0,
        nodes4: 0,
        nodes8: 0,
        kd_nodes: 0,
        words: 0,
    };

    /// A binary BVH over `count` primitives: [`nodes_needed`] nodes, one word per primitive id.
    #[must_use]
    pub const fn bvh(count: usize) -> Self {
        Self {
            nodes: nodes_needed(count),
            words: count,
            ..Self::NONE
        }
    }

    /// A 4-wide BVH over `count` primitives: the binary BVH it is collapsed from, then the
    /// collapse's scratch words after the primitive ids (build scratch both), and
    /// [`nodes4_needed`] wide nodes.
    #[must_use]
    pub const fn bvh4(count: usize) -> Self {
        Self {
            nodes4: nodes4_needed(count),
            words: count + collapse_words_needed(count, 4),
            ..Self::bvh(count)
        }
    }

    /// An 8-wide BVH over `count` primitives: as [`MemoryNeeded::bvh4`], with
    /// [`nodes8_needed`] wide nodes.
    #[must_use]
    pub const fn bvh8(count: usize) -> Self {
        Self {
            nodes8: nodes8_needed(count),
            words: count + collapse_words_needed(count, 8),
            ..Self::bvh(count)
        }
    }

    /// A kd-tree over `count` primitives: its node and reference budgets.
    #[must_use]
    pub const fn kdtree(count: usize) -> Self {
        Self {
            kd_nodes: kdtree::nodes_needed(count),
            words: kdtree::refs_needed(count),
            ..Self::NONE
        }
    }

    /// A uniform grid of the size its counting pass found: cell offsets and references.
    #[must_use]
    pub const fn grid(size: GridSize) -> Self {
        Self {
            words: size.cells.saturating_add(size.refs),
            ..Self::NONE
        }
    }

    /// What two builds take together.
    #[must_use]
    pub const fn add(self, o: Self) -> Self {
        Self {
            nodes: self.nodes.saturating_add(o.nodes),
            nodes4: self.nodes4.saturating_add(o.nodes4),
            nodes8: self.nodes8.saturating_add(o.nodes8),
            kd_nodes: self.kd_nodes.saturating_add(o.kd_nodes),
            words: self.words.saturating_add(o.words),
        }
    }

    /// The total in bytes for mode `S`.
    #[must_use]
    pub const fn bytes<S: Scalar>(&self) -> usize {
        self.nodes
            .saturating_mul(size_of::<Node<S>>())
            .saturating_add(self.nodes4.saturating_mul(size_of::<Node4<S>>()))
            .saturating_add(self.nodes8.saturating_mul(size_of::<Node8<S>>()))
            .saturating_add(self.kd_nodes.saturating_mul(size_of::<KdNode<S>>()))
            .saturating_add(self.words.saturating_mul(4))
    }

    /// The first buffer shorter in `available` than required here.
    #[must_use]
    pub const fn first_shortfall(&self, available: &MemoryNeeded) -> Option<Shortfall> {
        let pairs = [
            ("nodes", self.nodes, available.nodes),
            ("nodes4", self.nodes4, available.nodes4),
            ("nodes8", self.nodes8, available.nodes8),
            ("kd_nodes", self.kd_nodes, available.kd_nodes),
            ("words", self.words, available.words),
        ];
        let mut i = 0;
        while i < pairs.len() {
            let (field, needed, available) = pairs[i];
            if available < needed {
                return Some(Shortfall {
                    field,
                    needed,
                    available,
                });
            }
            i += 1;
        }
        None
    }
}
