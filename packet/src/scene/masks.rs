//! The ray masks of a scene query: one for all its rays, or one per ray.

/// The masks of a query's rays: a `u32` for all of them, or a `&[u32]` with one per ray (a
/// packet's lanes, a slice's rays). A ray's mask is ANDed with the masks on each instance path
/// ([`octoray_core::scene::Instance::mask`]) and the geometry's
/// ([`octoray_core::scene::Geometry::mask`]); no common bit, those primitives are not there for
/// it.
pub trait RayMasks: Copy {
    /// The mask of ray `i` (0 past the end of a slice: no ray there is traced).
    fn at(&self, i: usize) -> u32;
    /// The one mask of every ray, when the query has one.
    fn uniform(&self) -> Option<u32>;
    /// How many rays have a mask of their own (`None`: one mask for any number).
    fn count(&self) -> Option<usize>;
}

impl RayMasks for u32 {
    #[inline(always)]
    fn at(&self, _: usize) -> u32 {
        *self
    }
    #[inline(always)]
    fn uniform(&self) -> Option<u32> {
        Some(*self)
    }
    #[inline(always)]
    fn count(&self) -> Option<usize> {
        None
    }
}

impl RayMasks for &[u32] {
    #[inline(always)]
    fn at(&self, i: usize) -> u32 {
        self.get(i).copied().unwrap_or(0)
    }
    #[inline(always)]
    fn uniform(&self) -> Option<u32> {
        None
    }
    #[inline(always)]
    fn count(&self) -> Option<usize> {
        Some(self.len())
    }
}

/// Panics unless `masks` has one mask per ray (or one for all).
#[track_caller]
pub(super) fn check_masks<M: RayMasks>(what: &str, masks: M, rays: usize) {
    if let Some(n) = masks.count() {
        assert_eq!(n, rays, "octoray {what}: {n} ray masks for {rays} rays");
    }
}

/// The masks of `len` rays from ray `first` on: a slice's chunk.
#[derive(Clone, Copy)]
pub(super) struct Chunk<M> {
    pub masks: M,
    pub first: usize,
    pub len: usize,
}

impl<M: RayMasks> RayMasks for Chunk<M> {
    #[inline(always)]
    fn at(&self, i: usize) -> u32 {
        if i < self.len {
            self.masks.at(self.first + i)
        } else {
            0
        }
    }
    #[inline(always)]
    fn uniform(&self) -> Option<u32> {
        self.masks.uniform()
    }
    #[inline(always)]
    fn count(&self) -> Option<usize> {
        self.masks.count().map(|_| self.len)
    }
}
