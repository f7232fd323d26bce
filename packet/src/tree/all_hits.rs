//! Every hit along a ray, in order, into a caller's buffer: [`all_hits_ray`] and the collector
//! the scene's query shares.

use super::queries::{occluded_ray_with, occluded_with};
use core::cmp::Ordering;
use octoray_core::bvh::Bvh8Ref;
use octoray_core::hit::{Candidate, Hit, HitFilter};
use octoray_core::kernels::Kernel;
use octoray_core::lanes::Lanes;
use octoray_core::prim::Ray;

/// What an all-hits query stored: `out[..stored]` holds distinct hits in hit order, and
/// `complete` says whether they are all the hits after the cursor (else they are the first
/// `out.len()` of them, and the next call continues after `out[stored - 1]`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AllHits {
    /// Hits written to the front of the buffer.
    pub stored: usize,
    /// No hit was left out for want of room.
    pub complete: bool,
}

/// The hit order: `t`, then instance, geometry and primitive (a total order on hits, under
/// which two reports of one primitive at one `t` are one hit).
pub fn hit_order(a: &Hit, b: &Hit) -> Ordering {
    a.t.total_cmp(&b.t)
        .then(a.inst.cmp(&b.inst))
        .then(a.geom.cmp(&b.geom))
        .then(a.prim.cmp(&b.prim))
}

/// Inserts `item` into the sorted `out[..found.stored]` (ordered by `order`) unless an equal one
/// is there already or it falls past a full buffer's last (then `found` is incomplete); a
/// nearer one in a full buffer takes the last one's place. The buffer of every paged query.
pub(crate) fn insert_sorted<T: Copy>(
    out: &mut [T],
    found: &mut AllHits,
    item: T,
    order: impl Fn(&T, &T) -> Ordering,
) {
    let len = found.stored;
    let Err(at) = out[..len].binary_search_by(|x| order(x, &item)) else {
        return;
    };
    if len == out.len() {
        // A repeat of an item left out is never before the last one kept, so it stays out.
        found.complete = false;
        if at == len {
            return;
        }
        found.stored -= 1;
    }
    out.copy_within(at..found.stored, at + 1);
    out[at] = item;
    found.stored += 1;
}

/// Inserts `h` into the sorted hits unless it is at or before the cursor `after`
/// ([`insert_sorted`] in hit order).
fn insert(out: &mut [Hit], found: &mut AllHits, after: Option<Hit>, h: Hit) {
    if after.is_some_and(|a| hit_order(&h, &a) != Ordering::Greater) {
        return;
    }
    insert_sorted(out, found, h, hit_order);
}

/// The hit a filter is shown.
fn hit_of(c: &Candidate) -> Hit {
    Hit {
        t: c.t,
        u: c.u,
        v: c.v,
        prim: c.prim,
        geom: c.geom,
        inst: c.inst,
    }
}

/// No hit stored yet.
const NONE_YET: AllHits = AllHits {
    stored: 0,
    complete: true,
};

/// A filter that rejects every hit and keeps the first `out.len()` distinct ones after a cursor
/// in hit order, sorted: the walk then offers it every hit in range.
pub(crate) struct Collect<'o> {
    out: &'o mut [Hit],
    after: Option<Hit>,
    found: AllHits,
}

impl<'o> Collect<'o> {
    /// An empty collection into `out` of the hits after `after`.
    pub fn new(out: &'o mut [Hit], after: Option<Hit>) -> Self {
        Self {
            out,
            after,
            found: NONE_YET,
        }
    }

    /// What was stored.
    pub fn found(&self) -> AllHits {
        self.found
    }
}

impl HitFilter for Collect<'_> {
    fn accept(&mut self, c: &Candidate) -> bool {
        insert(self.out, &mut self.found, self.after, hit_of(c));
        false
    }
}

/// [`Collect`] for a slice of rays: ray `i`'s hits go to the `i`-th run of `out.len() /
/// found.len()` slots, its count to `found[i]`.
pub(crate) struct CollectEach<'o> {
    out: &'o mut [Hit],
    found: &'o mut [AllHits],
    /// The index of the walk's first ray in the slice (a walk over a chunk numbers its rays
    /// from 0).
    pub base: usize,
}

impl<'o> CollectEach<'o> {
    /// Empty collections; `out.len()` is a multiple of `found.len()`.
    pub fn new(out: &'o mut [Hit], found: &'o mut [AllHits]) -> Self {
        found.fill(NONE_YET);
        Self {
            out,
            found,
            base: 0,
        }
    }
}

impl HitFilter for CollectEach<'_> {
    fn accept(&mut self, c: &Candidate) -> bool {
        let cap = self.out.len() / self.found.len().max(1);
        let i = self.base + c.ray as usize;
        if let Some(found) = self.found.get_mut(i) {
            insert(&mut self.out[i * cap..][..cap], found, None, hit_of(c));
        }
        false
    }
}

/// Every hit of one ray in `[t_min, t_max]` with kernel `K`, nearest first, into `out`: each
/// primitive once (also where spatial splits put it in several leaves), after the cursor
/// `after` in [`hit_order`] (`None`: from the start). No allocation; the walk visits every box
/// the ray reaches in range.
///
/// With a buffer too small, `out` holds the first `out.len()` hits and [`AllHits::complete`] is
/// false: call again with `after = Some(out[stored - 1])` for the next ones.
///
/// ```
/// # #[cfg(all(feature = "triangle", feature = "alloc"))] {
/// use octoray_core::{bvh::Bvh8, glam::Vec3, kernels::Exact, prim::{Ray, VertexTriangle}};
/// use octoray_packet::{f32x8, tree::all_hits_ray};
/// // Three parallel squares' lower halves at z = 1, 2, 3.
/// let tris: Vec<_> = (1..=3)
///     .map(|z| {
///         let z = z as f32;
///         VertexTriangle::new(Vec3::new(-1.0, -1.0, z), Vec3::new(1.0, -1.0, z), Vec3::new(-1.0, 1.0, z))
///     })
///     .collect();
/// let bvh = Bvh8::build(&tris);
/// let ray = Ray::new(Vec3::new(-0.5, -0.5, 0.0), Vec3::Z);
/// let mut out = [octoray_core::hit::Hit::default(); 2];
/// let page = all_hits_ray::<f32x8, Exact>(bvh.as_ref(), &ray, None, &mut out);
/// assert_eq!((page.stored, page.complete), (2, false));
/// assert_eq!([out[0].t, out[1].t], [1.0, 2.0]);
/// let rest = all_hits_ray::<f32x8, Exact>(bvh.as_ref(), &ray, Some(out[1]), &mut out);
/// assert_eq!((rest.stored, rest.complete, out[0].t), (1, true, 3.0));
/// # }
/// ```
pub fn all_hits_ray<L: Lanes, K: Kernel<L>>(
    bvh: Bvh8Ref<'_, K::Prim>,
    ray: &Ray,
    after: Option<Hit>,
    out: &mut [Hit],
) -> AllHits {
    let mut collect = Collect::new(out, after);
    occluded_ray_with::<L, K, _>(bvh, ray, &mut collect);
    collect.found()
}

/// Every hit of each ray: ray `i`'s first `out.len() / rays.len()` hits in hit order into that
/// run of `out` (`out[i·cap..(i + 1)·cap]`), its count and completeness into `found[i]`; as
/// [`all_hits_ray`] ray by ray (continue a ray whose answer is incomplete with
/// [`all_hits_ray`] and its cursor), traced as packets where neighbouring rays share a
/// direction octant.
///
/// # Panics
/// When `found.len() != rays.len()`, or `out.len()` is not a multiple of `rays.len()`.
#[track_caller]
pub fn all_hits<L: Lanes, K: Kernel<L>>(
    bvh: Bvh8Ref<'_, K::Prim>,
    rays: &[Ray],
    out: &mut [Hit],
    found: &mut [AllHits],
) {
    in_chunks(rays, out, found, |_, chunk, occluded, collect| {
        occluded_with::<L, K, _>(bvh, chunk, occluded, collect);
    });
}

/// Calls `f` for every hit a paged all-hits `query` (given the cursor and a page, as
/// [`all_hits_ray`] takes them) reports, a page of `PAGE` at a time.
#[cfg(feature = "triangle")]
pub(crate) fn each_hit<const PAGE: usize>(
    mut query: impl FnMut(Option<Hit>, &mut [Hit]) -> AllHits,
    mut f: impl FnMut(&Hit),
) {
    let mut page = [Hit::default(); PAGE];
    let mut after = None;
    loop {
        let found = query(after, &mut page);
        page[..found.stored].iter().for_each(&mut f);
        if found.complete || found.stored == 0 {
            return;
        }
        after = Some(page[found.stored - 1]);
    }
}

/// The slice form of every all-hits query: checks the buffers' sizes, then has `walk` trace
/// the rays in chunks of 64 (its first ray's index, the chunk, an occlusion buffer of its
/// length) with one collector that files each ray's hits in its run of `out`.
///
/// # Panics
/// When `found.len() != rays.len()`, or `out.len()` is not a multiple of `rays.len()`.
#[track_caller]
pub(crate) fn in_chunks(
    rays: &[Ray],
    out: &mut [Hit],
    found: &mut [AllHits],
    mut walk: impl FnMut(usize, &[Ray], &mut [bool], &mut CollectEach<'_>),
) {
    assert_eq!(
        found.len(),
        rays.len(),
        "octoray: {} answers for {} rays",
        found.len(),
        rays.len()
    );
    assert!(
        out.len().is_multiple_of(rays.len()),
        "octoray: {} hit slots are not a whole number per ray for {} rays",
        out.len(),
        rays.len()
    );
    let mut collect = CollectEach::new(out, found);
    let mut occluded = [false; 64];
    for (k, chunk) in rays.chunks(64).enumerate() {
        collect.base = 64 * k;
        walk(64 * k, chunk, &mut occluded[..chunk.len()], &mut collect);
    }
}
