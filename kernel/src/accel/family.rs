//! Accelerator families: a structure chosen at compile time, so that code generic over a
//! family (the renderer) links that structure alone. [`AnyFamily`] is the run-time choice.

use super::any::AnyAccel;
use super::bvh::{BuildOptions, BuildSettings, Bvh};
use super::grid::{Grid, GridOptions};
use super::kdtree::{KdOptions, KdTree};
use super::memory::take;
use super::wide::{collapse_words_needed, Bvh4, Bvh8};
use super::{
    check_count, check_each, Accel, AccelKind, AccelMemory, BuildError, Linear, MemoryNeeded,
};
use crate::geom::Primitive;
use crate::scalar::Scalar;
use core::fmt::Debug;
use core::marker::PhantomData;

/// A kind of accelerator, named at compile time: what it builds over primitives `P`, with which
/// run-time options, into how much memory.
pub trait AccelFamily<S: Scalar>: Copy + Debug + 'static {
    /// The built structure over primitives `P`.
    type Accel<'a, P: Primitive<S> + 'a>: Accel<S> + Copy + Debug;
    /// What the caller chooses at run time.
    type Options: Copy + Debug + PartialEq;
    /// How the renderer builds its BVH over the objects (with its `Default` value):
    /// [`BuildOptions`] for every family but a [`BvhFamily`] with settings named at compile
    /// time, which builds it with that settings type, so a pass the family leaves out is not
    /// linked for the objects either.
    type TopLevel: BuildSettings + Default;
    /// Whether code generic over the family handles spheres. With `false`, sphere arms are
    /// constant-false branches (dead code) and sphere inputs are refused.
    const SPHERES: bool = true;

    /// The exact memory [`AccelFamily::build`] takes over `prims`.
    ///
    /// # Errors
    /// [`BuildError::TooManyPrims`], and what a counting pass rejects.
    fn memory_needed<P: Primitive<S>>(
        options: &Self::Options,
        prims: &[P],
    ) -> Result<MemoryNeeded, BuildError>;

    /// Builds over `prims`, taking [`AccelFamily::memory_needed`] from the front of `memory`.
    ///
    /// # Errors
    /// What the structure's builder reports.
    fn build<'a, P: Primitive<S> + 'a>(
        options: &Self::Options,
        prims: &'a [P],
        memory: &mut AccelMemory<'a, S>,
    ) -> Result<Self::Accel<'a, P>, BuildError>;
}

/// Any structure, chosen at run time by an [`AccelKind`]: [`AnyAccel`].
#[derive(Clone, Copy, Debug)]
pub struct AnyFamily;

/// Brute force, [`Linear`].
#[derive(Clone, Copy, Debug)]
pub struct LinearFamily;

/// The binary BVH, [`Bvh`], built with settings of type `B`: [`BuildOptions`] chosen at run
/// time, or a [`crate::bvh::StaticBuild`] that links one split rule and, if it names it, the
/// reinsertion pass.
#[derive(Clone, Copy, Debug)]
pub struct BvhFamily<B = BuildOptions>(PhantomData<B>);

/// The 4-wide BVH, [`Bvh4`].
#[derive(Clone, Copy, Debug)]
pub struct Bvh4Family;

/// The 8-wide BVH, [`Bvh8`].
#[derive(Clone, Copy, Debug)]
pub struct Bvh8Family;

/// The uniform grid, [`Grid`].
#[derive(Clone, Copy, Debug)]
pub struct GridFamily;

/// The kd-tree, [`KdTree`].
#[derive(Clone, Copy, Debug)]
pub struct KdTreeFamily;

/// Family `F` for scenes of triangles only: spheres are not linked ([`AccelFamily::SPHERES`]).
#[derive(Clone, Copy, Debug)]
pub struct TrianglesOnly<F>(PhantomData<F>);

impl<S: Scalar> AccelFamily<S> for AnyFamily {
    type Accel<'a, P: Primitive<S> + 'a> = AnyAccel<'a, S, P>;
    type Options = AccelKind;
    type TopLevel = BuildOptions;

    fn memory_needed<P: Primitive<S>>(
        kind: &AccelKind,
        prims: &[P],
    ) -> Result<MemoryNeeded, BuildError> {
        kind.memory_needed(prims)
    }

    fn build<'a, P: Primitive<S> + 'a>(
        kind: &AccelKind,
        prims: &'a [P],
        memory: &mut AccelMemory<'a, S>,
    ) -> Result<AnyAccel<'a, S, P>, BuildError> {
        AnyAccel::build(*kind, prims, memory)
    }
}

impl<S: Scalar> AccelFamily<S> for LinearFamily {
    type Accel<'a, P: Primitive<S> + 'a> = Linear<'a, S, P>;
    type Options = ();
    type TopLevel = BuildOptions;

    fn memory_needed<P: Primitive<S>>(_: &(), prims: &[P]) -> Result<MemoryNeeded, BuildError> {
        check_count(prims.len())?;
        Ok(MemoryNeeded::NONE)
    }

    fn build<'a, P: Primitive<S> + 'a>(
        _: &(),
        prims: &'a [P],
        _: &mut AccelMemory<'a, S>,
    ) -> Result<Linear<'a, S, P>, BuildError> {
        check_count(prims.len())?;
        check_each(prims)?;
        Ok(Linear::new(prims))
    }
}

impl<S: Scalar, B> AccelFamily<S> for BvhFamily<B>
where
    B: BuildSettings + Default + Debug + PartialEq + 'static,
{
    type Accel<'a, P: Primitive<S> + 'a> = Bvh<'a, S, P>;
    type Options = B;
    type TopLevel = B;

    fn memory_needed<P: Primitive<S>>(_: &B, prims: &[P]) -> Result<MemoryNeeded, BuildError> {
        check_count(prims.len())?;
        Ok(MemoryNeeded::bvh(prims.len()))
    }

    fn build<'a, P: Primitive<S> + 'a>(
        options: &B,
        prims: &'a [P],
        memory: &mut AccelMemory<'a, S>,
    ) -> Result<Bvh<'a, S, P>, BuildError> {
        binary_in(options, prims, memory)
    }
}

/// The binary BVH over `prims`, built into [`MemoryNeeded::bvh`] taken from `memory` (the
/// wide BVHs collapse it: for them it is build scratch).
fn binary_in<'a, S: Scalar, P: Primitive<S> + 'a, B: BuildSettings>(
    options: &B,
    prims: &'a [P],
    memory: &mut AccelMemory<'a, S>,
) -> Result<Bvh<'a, S, P>, BuildError> {
    let need = MemoryNeeded::bvh(prims.len());
    let nodes = take(&mut memory.nodes, need.nodes);
    let ids = take(&mut memory.words, need.words);
    Bvh::build(prims, nodes, ids, *options)
}

impl<S: Scalar> AccelFamily<S> for Bvh4Family {
    type Accel<'a, P: Primitive<S> + 'a> = Bvh4<'a, S, P>;
    type Options = BuildOptions;
    type TopLevel = BuildOptions;

    fn memory_needed<P: Primitive<S>>(
        _: &BuildOptions,
        prims: &[P],
    ) -> Result<MemoryNeeded, BuildError> {
        check_count(prims.len())?;
        Ok(MemoryNeeded::bvh4(prims.len()))
    }

    fn build<'a, P: Primitive<S> + 'a>(
        options: &BuildOptions,
        prims: &'a [P],
        memory: &mut AccelMemory<'a, S>,
    ) -> Result<Bvh4<'a, S, P>, BuildError> {
        let nodes4 = take(&mut memory.nodes4, MemoryNeeded::bvh4(prims.len()).nodes4);
        let binary = binary_in(options, prims, memory)?;
        let scratch = take(&mut memory.words, collapse_words_needed(prims.len(), 4));
        Bvh4::collapse(&binary, nodes4, scratch)
    }
}

impl<S: Scalar> AccelFamily<S> for Bvh8Family {
    type Accel<'a, P: Primitive<S> + 'a> = Bvh8<'a, S, P>;
    type Options = BuildOptions;
    type TopLevel = BuildOptions;

    fn memory_needed<P: Primitive<S>>(
        _: &BuildOptions,
        prims: &[P],
    ) -> Result<MemoryNeeded, BuildError> {
        check_count(prims.len())?;
        Ok(MemoryNeeded::bvh8(prims.len()))
    }

    fn build<'a, P: Primitive<S> + 'a>(
        options: &BuildOptions,
        prims: &'a [P],
        memory: &mut AccelMemory<'a, S>,
    ) -> Result<Bvh8<'a, S, P>, BuildError> {
        let nodes8 = take(&mut memory.nodes8, MemoryNeeded::bvh8(prims.len()).nodes8);
        let binary = binary_in(options, prims, memory)?;
        let scratch = take(&mut memory.words, collapse_words_needed(prims.len(), 8));
        Bvh8::collapse(&binary, nodes8, scratch)
    }
}

impl<S: Scalar> AccelFamily<S> for GridFamily {
    type Accel<'a, P: Primitive<S> + 'a> = Grid<'a, S, P>;
    type Options = GridOptions;
    type TopLevel = BuildOptions;

    fn memory_needed<P: Primitive<S>>(
        options: &GridOptions,
        prims: &[P],
    ) -> Result<MemoryNeeded, BuildError> {
        let size = Grid::<S, P>::size_for(prims, *options)?;
        Ok(MemoryNeeded::grid(size))
    }

    fn build<'a, P: Primitive<S> + 'a>(
        options: &GridOptions,
        prims: &'a [P],
        memory: &mut AccelMemory<'a, S>,
    ) -> Result<Grid<'a, S, P>, BuildError> {
        let size = Grid::<S, P>::size_for(prims, *options)?;
        let cells = take(&mut memory.words, size.cells);
        let refs = take(&mut memory.words, size.refs);
        Grid::build(prims, cells, refs, *options)
    }
}

impl<S: Scalar> AccelFamily<S> for KdTreeFamily {
    type Accel<'a, P: Primitive<S> + 'a> = KdTree<'a, S, P>;
    type Options = KdOptions;
    type TopLevel = BuildOptions;

    fn memory_needed<P: Primitive<S>>(
        _: &KdOptions,
        prims: &[P],
    ) -> Result<MemoryNeeded, BuildError> {
        check_count(prims.len())?;
        Ok(MemoryNeeded::kdtree(prims.len()))
    }

    fn build<'a, P: Primitive<S> + 'a>(
        options: &KdOptions,
        prims: &'a [P],
        memory: &mut AccelMemory<'a, S>,
    ) -> Result<KdTree<'a, S, P>, BuildError> {
        let need = MemoryNeeded::kdtree(prims.len());
        let nodes = take(&mut memory.kd_nodes, need.kd_nodes);
        let refs = take(&mut memory.words, need.words);
        KdTree::build(prims, nodes, refs, *options)
    }
}

impl<S: Scalar, F: AccelFamily<S>> AccelFamily<S> for TrianglesOnly<F> {
    type Accel<'a, P: Primitive<S> + 'a> = F::Accel<'a, P>;
    type Options = F::Options;
    type TopLevel = F::TopLevel;
    const SPHERES: bool = false;

    fn memory_needed<P: Primitive<S>>(
        options: &F::Options,
        prims: &[P],
    ) -> Result<MemoryNeeded, BuildError> {
        F::memory_needed(options, prims)
    }

    fn build<'a, P: Primitive<S> + 'a>(
        options: &F::Options,
        prims: &'a [P],
        memory: &mut AccelMemory<'a, S>,
    ) -> Result<F::Accel<'a, P>, BuildError> {
        F::build(options, prims, memory)
    }
}
