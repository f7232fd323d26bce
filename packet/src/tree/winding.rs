//! The generalized winding number of any triangle mesh: [`generalized_winding_number`], far
//! clusters by their moments, near ones triangle by triangle.

use arrayvec::ArrayVec;
use octoray_core::bvh::{WindingTree, EMPTY, STACK, WIDTH};
use octoray_core::glam::Vec3;
use octoray_core::kernels::triangle::solid_angle::{AngleLanes, Cluster};
use octoray_core::lanes::{Lanes, V3};
use octoray_core::prim::{BlockRows, Primitive, VertexTriangle, BLOCK};
use wide::f64x8;

/// The generalized winding number of the mesh in `tree` at `point` (Jacobson, Kavan and
/// Sorkine-Hornung 2013): the solid angles its triangles subtend there, summed and divided by
/// 4π. For a closed, outward-oriented mesh it is 1 inside and 0 outside (the exact
/// [`winding_number`](super::winding_number) of a [`Solid`](octoray_core::bvh::Solid));
/// for an open, non-manifold or self-intersecting one it varies smoothly away from the surface
/// and a threshold at ½ classifies inside and outside robustly (a point in the plane of a
/// triangle gets 0 from it, so on the surface of a closed mesh the answer is ½).
///
/// # Error bound
/// `|answer − exact| ≤ tolerance` plus the rounding of the f64 sum (a few units of 2⁻⁵² per
/// triangle or cluster summed, relative to their solid angles). A cluster of the tree is summed
/// by its moments (the far field of [`Cluster`](octoray_core::kernels::triangle::solid_angle::Cluster))
/// where its proven error bound is at most `tolerance` times its share of the mesh's area, so
/// the errors add up to at most `tolerance`; elsewhere its triangles' solid angles are summed
/// one by one. `tolerance = 0` (or negative, or NaN) sums every triangle. Larger tolerances
/// are faster: `0.1` classifies points at least that far from ½ exactly and skips most of a
/// large mesh.
///
/// A non-finite point gives NaN; a mesh with no area gives 0.
///
/// ```
/// # #[cfg(all(feature = "triangle", feature = "alloc"))] {
/// use octoray_core::{bvh::{Bvh8, WindingTree}, glam::Vec3, prim::VertexTriangle};
/// use octoray_packet::tree::generalized_winding_number;
/// // A tetrahedron without its base (z = 0): open.
/// let p = [Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0), Vec3::Z];
/// let tris: Vec<_> = [[0, 1, 3], [1, 2, 3], [2, 0, 3]]
///     .iter()
///     .map(|&[a, b, c]| VertexTriangle::new(p[a], p[b], p[c]))
///     .collect();
/// let bvh = Bvh8::build(&tris);
/// let tree = WindingTree::new(bvh.as_ref());
/// let inside = generalized_winding_number(&tree, Vec3::new(0.0, -0.2, 0.3), 1e-6);
/// let outside = generalized_winding_number(&tree, Vec3::new(3.0, 2.0, 1.0), 1e-6);
/// assert!(inside > 0.5 && outside.abs() < 0.5);
/// // In the plane of the missing base, half of the space around the point is the cap's.
/// let base = generalized_winding_number(&tree, Vec3::new(0.0, -0.2, 0.0), 0.0);
/// assert!((base - 0.5).abs() < 1e-12);
/// # }
/// ```
pub fn generalized_winding_number(tree: &WindingTree<'_>, point: Vec3, tolerance: f64) -> f64 {
    if !point.is_finite() {
        return f64::NAN;
    }
    let p = point.to_array().map(f64::from);
    let mut budget = Budget {
        // A hair under the tolerance, for the rounding of the comparisons.
        left: if tolerance > 0.0 {
            tolerance * (1.0 - 1e-9)
        } else {
            0.0
        },
        unresolved: tree.area(),
    };
    // Near triangles a block at a time, each lane its own product; far clusters as numbers.
    let mut near = AngleLanes::<f64x8>::new();
    let mut far = 0.0;
    let q = V3::new(f64x8::splat(p[0]), f64x8::splat(p[1]), f64x8::splat(p[2]));
    let bvh = tree.bvh();
    let mut stack = ArrayVec::<u32, STACK>::new();
    if !bvh.nodes().is_empty() {
        stack.push(0);
    }
    while let Some(n) = stack.pop() {
        let (Some(node), Some(clusters)) = (bvh.nodes().get(n as usize), tree.clusters(n as usize))
        else {
            continue;
        };
        // The node's far clusters first (each spends less than its share), then the rest.
        let mut rest = 0u32;
        for s in (0..WIDTH).filter(|&s| node.child[s] != EMPTY) {
            let c = &clusters[s];
            if budget.spend(c, p) {
                far += c.far_field(p);
            } else {
                rest |= 1 << s;
            }
        }
        for s in (0..WIDTH).filter(|&s| rest >> s & 1 == 1) {
            let (child, count) = (node.child[s], node.count[s]);
            if count == 0 {
                // A validated tree is at most MAX_DEPTH deep, so the stack never fills.
                let _ = stack.try_push(child);
                continue;
            }
            budget.unresolved -= clusters[s].area;
            let first = child as usize / BLOCK;
            let blocks = (count as usize).div_ceil(BLOCK);
            for b in first..first.saturating_add(blocks).min(bvh.ids().len() / BLOCK) {
                let rows = BlockRows::new::<VertexTriangle>(bvh.block_of(b * BLOCK), 0);
                let t = VertexTriangle::from_words::<f64x8, _>(&rows);
                let keep = f64x8::mask_from_bits(tree.counted(b));
                near.add_triangles(t.v0, t.v1, t.v2, q, keep);
            }
        }
    }
    (near.total() + far) / (4.0 * core::f64::consts::PI)
}

/// The error the far fields may still add, and the area not yet summed: a cluster may spend
/// its share of what is left, so what far clusters leave unspent and near ones, summed
/// exactly, do not use passes on to the clusters after them; the total spent never exceeds
/// the tolerance.
struct Budget {
    left: f64,
    unresolved: f64,
}

impl Budget {
    /// Whether cluster `c` may be summed by its far field from `p`: its error bound within its
    /// share; if so, spent and its area resolved.
    fn spend(&mut self, c: &Cluster, p: [f64; 3]) -> bool {
        let (d, outside) = c.distance(p);
        if self.left <= 0.0 || !outside {
            return false;
        }
        let bound = c.error_bound(d);
        let share = self.left * (c.area / self.unresolved.max(c.area));
        if bound.is_nan() || bound > share {
            return false;
        }
        self.left -= bound;
        self.unresolved -= c.area;
        true
    }
}
