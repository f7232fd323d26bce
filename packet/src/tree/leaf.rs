//! What a walk does at a leaf ([`Leaf`]): test primitives ([`Prims`], here) or enter instances
//! (the scene's top level).

use super::epilog::{accepts, better, bound, Best, PacketBest, UNPLACED};
use octoray_core::bvh::Bvh8Ref;
use octoray_core::hit::HitFilter;
use octoray_core::kernels::Kernel;
use octoray_core::lanes::{LaneMask, Lanes};
use octoray_core::prim::{BlockLane, BlockRows, RayLanes, BLOCK};
use octoray_core::scene::{Geometry, Member};

/// What a walk does with the slots `first..first + count` of a leaf.
pub(crate) trait Leaf<L: Lanes> {
    /// What the leaf tests need of a ray or packet, computed once per walk.
    type Pre;
    /// Prepares `rays` (one ray broadcast, or a packet).
    fn prepare(&self, rays: &RayLanes<L>) -> Self::Pre;
    /// One ray (`rl`, broadcast to every lane) against the slots: `best` carries the hit so far
    /// in and the best one out, `t_bound` its [`bound`] (kept equal to it). With `ANY`, returns
    /// `true` at the first accepted hit.
    #[allow(clippy::too_many_arguments)] // the walk's state, passed down once per leaf
    fn single<F: HitFilter, const ANY: bool>(
        &self,
        pre: &Self::Pre,
        first: usize,
        count: usize,
        rl: &RayLanes<L>,
        best: &mut Option<Best<L::Scalar>>,
        t_bound: &mut L::Scalar,
        filter: &mut F,
        ray_id: u32,
    ) -> bool;
    /// The lanes `live` of a packet against the slots: updates `best` (with `ANY`, a lane's
    /// first accepted hit finishes it).
    #[allow(clippy::too_many_arguments)] // as `single`
    fn packet<F: HitFilter, const ANY: bool>(
        &self,
        pre: &Self::Pre,
        first: usize,
        count: usize,
        rays: &RayLanes<L>,
        live: L::Mask,
        best: &mut PacketBest<L>,
        filter: &mut F,
        ray_base: u32,
    );
}

/// A tree's leaves: primitives tested with kernel `K`, hits reported for instance `inst` (and
/// geometry `geom` when the tree holds one; with `MANY`, a tree of several geometries, each
/// hit's is found in `members` and counts only where that geometry's mask shares a bit with
/// `mask`: a separate instantiation, so a tree of one geometry pays nothing for it).
pub(crate) struct Prims<'a, L: Lanes, K: Kernel<L>, const MANY: bool> {
    pub bvh: Bvh8Ref<'a, K::Prim>,
    pub geom: u32,
    pub inst: u32,
    pub members: Members<'a>,
}

/// The geometries of a tree of several (empty `members`: one, reported as `Prims::geom`).
#[derive(Clone, Copy)]
pub(crate) struct Members<'a> {
    pub members: &'a [Member],
    pub geoms: &'a [Geometry],
    /// The query's mask and the instance's.
    pub mask: u32,
    /// Every member admitted by `mask`: without a filter, a hit's geometry is found only once
    /// the walk is done ([`UNPLACED`], then [`Members::place`]).
    pub all_admitted: bool,
}

impl Members<'_> {
    /// One geometry: nothing to find.
    pub const ONE: Self = Members {
        members: &[],
        geoms: &[],
        mask: u32::MAX,
        all_admitted: true,
    };

    /// Geometry and primitive of the tree's primitive `id`, or `None` where the geometry's mask
    /// keeps its hits out.
    #[inline]
    pub fn place(&self, id: u32) -> Option<(u32, u32)> {
        // Members start at 0 in increasing order (validated): the last one starting at or
        // before `id`.
        let k = self.members.partition_point(|x| x.first_prim <= id).max(1) - 1;
        let member = self.members.get(k)?;
        let g = self.geoms.get(member.geom as usize)?;
        (g.mask & self.mask != 0).then(|| (member.geom, id.wrapping_sub(member.first_prim)))
    }

    /// [`Members::place`], or `(geom, id)` in a tree of the one geometry `geom` (no members).
    #[inline]
    pub fn locate(&self, geom: u32, id: u32) -> Option<(u32, u32)> {
        if self.members.is_empty() {
            Some((geom, id))
        } else {
            self.place(id)
        }
    }
}

impl<L: Lanes, K: Kernel<L>, const MANY: bool> Prims<'_, L, K, MANY> {
    /// Geometry and primitive of the tree's primitive `id` for a walk with filter `F`, or
    /// `None` where the geometry's mask keeps its hits out; `(UNPLACED, id)` when that is left
    /// until the walk is done (no filter, every member admitted).
    #[cfg_attr(not(debug_assertions), inline(always))]
    fn place<F: HitFilter>(&self, id: u32) -> Option<(u32, u32)> {
        let m = &self.members;
        if !MANY {
            return Some((self.geom, id));
        }
        if F::ACCEPTS_ALL && m.all_admitted {
            return Some((UNPLACED, id));
        }
        m.place(id)
    }
}

impl<L: Lanes, K: Kernel<L>, const MANY: bool> Leaf<L> for Prims<'_, L, K, MANY> {
    type Pre = K::Pre;

    #[cfg_attr(not(debug_assertions), inline(always))]
    fn prepare(&self, rays: &RayLanes<L>) -> K::Pre {
        K::prepare(rays)
    }

    #[cfg_attr(not(debug_assertions), inline(always))]
    fn single<F: HitFilter, const ANY: bool>(
        &self,
        pre: &K::Pre,
        first: usize,
        count: usize,
        rl: &RayLanes<L>,
        best: &mut Option<Best<L::Scalar>>,
        t_bound: &mut L::Scalar,
        filter: &mut F,
        ray_id: u32,
    ) -> bool {
        let bvh = self.bvh;
        let t_max = rl.t_max.lane(0);
        let mut ray = *rl;
        // One block at a time (a leaf starts a block: `first` is a multiple of BLOCK); at fewer
        // than BLOCK lanes, a block in several calls. A leaf holds at least one slot, so each
        // loop runs its body before it tests (at BLOCK lanes or more the inner one runs once).
        let end = first + count;
        let mut at = first;
        loop {
            let block = bvh.block_of(at);
            let in_block = (end - at).min(BLOCK);
            let mut sub = 0;
            loop {
                ray.active = L::first_lanes(in_block - sub);
                if !K::EXACT_T_MAX {
                    ray.t_max = L::splat_scalar(*t_bound);
                }
                let rows = BlockRows::new::<K::Prim>(block, sub);
                let h = K::intersect_words(&ray, pre, &rows);
                let mut bits = h.mask.bitmask();
                if ANY && F::ACCEPTS_ALL && bits != 0 && (!MANY || self.members.all_admitted) {
                    return true;
                }
                let mut moved = false;
                while bits != 0 {
                    let i = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    let id = bvh.ids()[at + sub + i];
                    let Some((geom, prim)) = self.place::<F>(id) else {
                        continue;
                    };
                    let hit = Best::lane(&h, i, id, (prim, geom, self.inst));
                    if (ANY || better(hit.t, hit.inst, hit.id, best))
                        && accepts(filter, &hit, ray_id)
                    {
                        if ANY {
                            return true;
                        }
                        *best = Some(hit);
                        moved = true;
                    }
                }
                if moved {
                    *t_bound = bound(t_max, best);
                }
                sub += L::LANES;
                if L::LANES >= BLOCK || sub >= in_block {
                    break;
                }
            }
            at += BLOCK;
            if at >= end {
                break;
            }
        }
        false
    }

    #[cfg_attr(not(debug_assertions), inline(always))]
    fn packet<F: HitFilter, const ANY: bool>(
        &self,
        pre: &K::Pre,
        first: usize,
        count: usize,
        rays: &RayLanes<L>,
        live: L::Mask,
        best: &mut PacketBest<L>,
        filter: &mut F,
        ray_base: u32,
    ) {
        let bvh = self.bvh;
        let mut ray = *rays;
        ray.active = live;
        // The block's rows found once per block, not per slot (`start`: the block's first slot).
        let (mut block, mut start) = (bvh.block_of(first), first - first % BLOCK);
        for k in first..first + count {
            if k - start >= BLOCK {
                (block, start) = (bvh.block_of(k), k);
            }
            ray.t_max = if K::EXACT_T_MAX {
                rays.t_max
            } else {
                best.cull
            };
            let prim = BlockLane::new::<K::Prim>(block, k - start);
            let h = K::intersect_words(&ray, pre, &prim);
            if h.mask.none() {
                continue;
            }
            let id = bvh.ids()[k];
            let Some((geom, local)) = self.place::<F>(id) else {
                continue;
            };
            let mut m = h.mask & (!best.mask | h.t.lt(best.t));
            let tie = h.mask & best.mask & !h.t.ne(best.t);
            if tie.any() {
                let mut lower = 0;
                let mut tb = tie.bitmask();
                while tb != 0 {
                    let i = tb.trailing_zeros() as usize;
                    tb &= tb - 1;
                    if (self.inst, id) < (L::index_lane(best.inst, i), L::index_lane(best.id, i)) {
                        lower |= 1 << i;
                    }
                }
                m = m | (tie & L::mask_from_bits(lower));
            }
            if !F::ACCEPTS_ALL {
                let (mut mb, mut keep) = (m.bitmask(), 0);
                while mb != 0 {
                    let i = mb.trailing_zeros() as usize;
                    mb &= mb - 1;
                    let hit = Best::lane(&h, i, id, (local, geom, self.inst));
                    if accepts(filter, &hit, ray_base + i as u32) {
                        keep |= 1 << i;
                    }
                }
                m = m & L::mask_from_bits(keep);
            }
            best.mask = best.mask | m;
            best.t = L::select(m, h.t, best.t);
            best.u = L::select(m, h.u, best.u);
            best.v = L::select(m, h.v, best.v);
            best.scale = L::select(m, h.scale, best.scale);
            best.id = L::select_index(m, L::splat_index(id), best.id);
            best.prim = L::select_index(m, L::splat_index(local), best.prim);
            best.geom = L::select_index(m, L::splat_index(geom), best.geom);
            best.unplaced |= geom == UNPLACED && m.any();
            best.inst = L::select_index(m, L::splat_index(self.inst), best.inst);
            if ANY {
                ray.active = ray.active & !best.mask;
                if ray.active.none() {
                    break;
                }
            } else {
                best.cull = L::select(m, best.t.loosen(rays.t_max), best.cull);
                best.moved = true;
            }
        }
    }
}
