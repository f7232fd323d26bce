//! A tree of triangles with each slot's far-field moments: what the generalized winding number of
//! a mesh that need not be closed sums.

use super::{Bvh8Ref, EMPTY, PAD, WIDTH};
use crate::kernels::triangle::solid_angle::Cluster;
use crate::prim::{BlockLane, Primitive, VertexTriangle, BLOCK};
use alloc::vec;
use alloc::vec::Vec;

/// A tree of triangles and, for every used slot of every node, the [`Cluster`] of the triangles
/// below it (area, area vector, first moment about a centre, and a radius around the centre that
/// holds them): `octoray-packet`'s `tree::generalized_winding_number` sums a far cluster by
/// its moments and a near one triangle by triangle.
///
/// Any triangle soup works: open, non-manifold, self-intersecting or inconsistently oriented.
/// A triangle that spatial splits put in several leaves counts once (at its first slot in leaf
/// order). Built in time and memory linear in the tree (`WIDTH` clusters of 17 `f64` per node).
#[derive(Clone, Debug)]
pub struct WindingTree<'a> {
    bvh: Bvh8Ref<'a, VertexTriangle>,
    /// `clusters[node][slot]`.
    clusters: Vec<[Cluster; WIDTH]>,
    /// Per block, the slots whose triangle counts there (bit `i`: slot `i` of the block holds
    /// the first reference to its triangle in leaf order).
    counted: Vec<u8>,
    area: f64,
}

/// Block slot `k`'s triangle as f64 vertices.
fn triangle(bvh: Bvh8Ref<'_, VertexTriangle>, k: usize) -> [[f64; 3]; 3] {
    let t = VertexTriangle::from_words::<f32, _>(&BlockLane::new::<VertexTriangle>(
        bvh.block_of(k),
        k % BLOCK,
    ));
    [t.v0, t.v1, t.v2].map(|v| [f64::from(v.x), f64::from(v.y), f64::from(v.z)])
}

/// The centre of the box holding the points `lo..hi` (each axis), or the origin when empty.
fn centre(lo: [f64; 3], hi: [f64; 3]) -> [f64; 3] {
    core::array::from_fn(|k| {
        if lo[k] <= hi[k] {
            0.5 * lo[k] + 0.5 * hi[k]
        } else {
            0.0
        }
    })
}

impl<'a> WindingTree<'a> {
    /// The moments of every slot of `bvh`, bottom up.
    pub fn new(bvh: Bvh8Ref<'a, VertexTriangle>) -> Self {
        let counted = first_references(bvh);
        let nodes = bvh.nodes();
        let mut clusters = vec![[Cluster::default(); WIDTH]; nodes.len()];
        // A child's index is above its parent's: in reverse order, children come first.
        for n in (0..nodes.len()).rev() {
            let slots: [Cluster; WIDTH] = core::array::from_fn(|s| {
                let (child, count) = (nodes[n].child[s], nodes[n].count[s]);
                if child == EMPTY {
                    Cluster::default()
                } else if count == 0 {
                    merge(clusters.get(child as usize).map_or(&[][..], |c| &c[..]))
                } else {
                    leaf(bvh, &counted, child as usize, count as usize)
                }
            });
            clusters[n] = slots;
        }
        let area = clusters.first().map_or(0.0, |c| merge(c).area);
        Self {
            bvh,
            clusters,
            counted,
            area,
        }
    }

    /// The tree.
    pub fn bvh(&self) -> Bvh8Ref<'a, VertexTriangle> {
        self.bvh
    }

    /// The clusters of node `n`'s slots (`None` past the last node).
    pub fn clusters(&self, n: usize) -> Option<&[Cluster; WIDTH]> {
        self.clusters.get(n)
    }

    /// The slots of block `b` whose triangles are summed there, as bits (a triangle in several
    /// leaves counts at its first slot in leaf order; 0 on padding and past the last block).
    pub fn counted(&self, b: usize) -> u32 {
        self.counted.get(b).map_or(0, |&m| u32::from(m))
    }

    /// The triangles' total area.
    pub fn area(&self) -> f64 {
        self.area
    }
}

/// For each block, the slots holding the first reference to their triangle in leaf order.
fn first_references(bvh: Bvh8Ref<'_, VertexTriangle>) -> Vec<u8> {
    let mut seen = vec![false; bvh.prims()];
    let mut counted = vec![0u8; bvh.ids().len().div_ceil(BLOCK)];
    for (k, &id) in bvh.ids().iter().enumerate() {
        if id == PAD {
            continue;
        }
        if let Some(s) = seen.get_mut(id as usize) {
            if !*s {
                counted[k / BLOCK] |= 1 << (k % BLOCK);
            }
            *s = true;
        }
    }
    counted
}

/// The cluster of a leaf's counted triangles, about the centre of their vertices' box.
fn leaf(bvh: Bvh8Ref<'_, VertexTriangle>, counted: &[u8], first: usize, count: usize) -> Cluster {
    let end = first.saturating_add(count).min(counted.len() * BLOCK);
    let slots = || {
        (first..end)
            .filter(|&k| counted[k / BLOCK] >> (k % BLOCK) & 1 == 1)
            .map(|k| triangle(bvh, k))
    };
    let finite = |t: &[[f64; 3]; 3]| t.iter().flatten().all(|x| x.is_finite());
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for v in slots().filter(finite).flatten() {
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    let mut c = Cluster::empty(centre(lo, hi));
    for t in slots() {
        c.add(&Cluster::triangle(t, c.centre));
    }
    c
}

/// The clusters of a node's slots as one, about the centre of the box holding their balls.
fn merge(slots: &[Cluster]) -> Cluster {
    let used = || slots.iter().filter(|c| c.area > 0.0 || c.radius > 0.0);
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for c in used() {
        for k in 0..3 {
            lo[k] = lo[k].min(c.centre[k] - c.radius);
            hi[k] = hi[k].max(c.centre[k] + c.radius);
        }
    }
    let mut m = Cluster::empty(centre(lo, hi));
    for c in used() {
        m.add(c);
    }
    m
}
