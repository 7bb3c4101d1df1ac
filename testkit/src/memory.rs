//! Owned caller memory for accelerator builds, sized exactly from [`MemoryNeeded`].

use raykernel::{
    AccelKind, AccelMemory, KdNode, MemoryNeeded, Node, Node4, Node8, Primitive, Scalar,
};
use std::vec::Vec;

/// The five buffers of an [`AccelMemory`], owned. Resizing keeps the allocations, so one value
/// serves a sequence of builds.
#[derive(Debug)]
pub struct OwnedMemory<S: Scalar> {
    nodes: Vec<Node<S>>,
    nodes4: Vec<Node4<S>>,
    nodes8: Vec<Node8<S>>,
    kd_nodes: Vec<KdNode<S>>,
    words: Vec<u32>,
}

impl<S: Scalar> Default for OwnedMemory<S> {
    /// No memory at all (enough for brute force and empty inputs).
    fn default() -> Self {
        Self::sized(MemoryNeeded::NONE)
    }
}

impl<S: Scalar> OwnedMemory<S> {
    /// Buffers of exactly the lengths `need` gives.
    pub fn sized(need: MemoryNeeded) -> Self {
        let mut memory = Self {
            nodes: Vec::new(),
            nodes4: Vec::new(),
            nodes8: Vec::new(),
            kd_nodes: Vec::new(),
            words: Vec::new(),
        };
        memory.resize(need);
        memory
    }

    /// Exactly the memory `kind` takes over `prims`; panics (naming the kind) if
    /// [`AccelKind::memory_needed`] rejects them.
    pub fn for_kind<P: Primitive<S>>(kind: AccelKind, prims: &[P]) -> Self {
        Self::sized(Self::needed(kind, prims))
    }

    /// What `kind` takes over `prims`; panics (naming the kind) on an error.
    pub fn needed<P: Primitive<S>>(kind: AccelKind, prims: &[P]) -> MemoryNeeded {
        kind.memory_needed(prims)
            .unwrap_or_else(|e| panic!("{} {kind} memory for {} prims: {e}", S::NAME, prims.len()))
    }

    /// Sets every buffer to exactly the length `need` gives.
    pub fn resize(&mut self, need: MemoryNeeded) {
        self.nodes.resize(need.nodes, Node::EMPTY);
        self.nodes4.resize(need.nodes4, Node4::EMPTY);
        self.nodes8.resize(need.nodes8, Node8::EMPTY);
        self.kd_nodes.resize(need.kd_nodes, KdNode::EMPTY);
        self.words.resize(need.words, 0);
    }

    /// The buffers as caller memory.
    pub fn memory(&mut self) -> AccelMemory<'_, S> {
        AccelMemory {
            nodes: &mut self.nodes,
            nodes4: &mut self.nodes4,
            nodes8: &mut self.nodes8,
            kd_nodes: &mut self.kd_nodes,
            words: &mut self.words,
        }
    }
}
