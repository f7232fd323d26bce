//! The scene-level peers, each built and traversed the way its documentation shows, on the same
//! triangles and rays as octoray's rows:
//!
//! - [`ObvhsScene`]: obvhs 0.4's CWBVH (`build_cwbvh_from_tris` with `medium_build`) and its own
//!   traversal (`ray_traverse`, `ray_traverse_miss`) with `Triangle::intersect`.
//! - [`BvhScene`]: bvh 0.13 (`Bvh::build`, `traverse` for the candidates, then
//!   `Ray::intersects_triangle`, which culls back faces).
//! - [`crate::embree`]: Embree 3 through its C API, loaded at run time.

use glam::Vec3;
use octoray::prim::Ray;
use std::time::{Duration, Instant};

/// obvhs's CWBVH over a triangle soup.
pub struct ObvhsScene {
    bvh: obvhs::cwbvh::CwBvh,
    tris: Vec<obvhs::triangle::Triangle>,
}

impl ObvhsScene {
    /// Builds with `medium_build` on one thread (the caller's rayon pool is not used by obvhs's
    /// builder unless its feature is on); returns the scene and the build's wall time.
    pub fn build(tris: &[[Vec3; 3]]) -> (Self, Duration) {
        let tris = crate::peers::obvhs_tris(tris);
        let start = Instant::now();
        let mut core = Duration::ZERO;
        let bvh = obvhs::cwbvh::builder::build_cwbvh_from_tris(
            &tris,
            obvhs::BvhBuildParams::medium_build(),
            &mut core,
        );
        (Self { bvh, tris }, start.elapsed())
    }

    /// The tree's SAH cost with the conventional unit costs octoray's `BuildStats::sah_cost`
    /// uses: 1 for the root, plus per child `area/area(root)`, times its primitive count for a
    /// leaf (obvhs's quantised child boxes, which are conservative like octoray's widened ones).
    /// Returned as (node term: 1 + Σ inner children's areas, leaf term: Σ leaf area × count,
    /// leaf term in blocks of 8: Σ leaf area × ⌈count/8⌉).
    pub fn sah_cost(&self) -> (f32, f32, f32) {
        if self.bvh.nodes.is_empty() {
            return (0.0, 0.0, 0.0);
        }
        // The scene's box (the root node's own box is its quantisation grid, up to twice as
        // wide per axis).
        let root_area = self.bvh.total_aabb.half_area().max(f32::MIN_POSITIVE);
        let (mut nodes, mut leaves, mut blocks) = (1.0, 0.0, 0.0);
        for n in &self.bvh.nodes {
            for c in 0..8 {
                if n.is_child_empty(c) {
                    continue;
                }
                let area = n.child_aabb(c).half_area() / root_area;
                if n.is_leaf(c) {
                    let count = n.child_primitives(c).1;
                    leaves += area * count as f32;
                    blocks += area * count.div_ceil(8) as f32;
                } else {
                    nodes += area;
                }
            }
        }
        (nodes, leaves, blocks)
    }

    fn ray(r: &Ray) -> obvhs::ray::Ray {
        obvhs::ray::Ray::new(r.origin.into(), r.dir.into(), r.t_min, r.t_max)
    }

    /// Closest hit of every ray; returns the number of hits.
    pub fn closest(&self, rays: &[Ray]) -> u64 {
        let mut hits = 0;
        for r in rays {
            let mut hit = obvhs::ray::RayHit::none();
            let found = self.bvh.ray_traverse(Self::ray(r), &mut hit, |ray, id| {
                self.tris[self.bvh.primitive_indices[id] as usize].intersect(ray)
            });
            hits += u64::from(found);
        }
        hits
    }

    /// Occlusion of every ray (first hit ends the walk); returns the number occluded.
    pub fn any(&self, rays: &[Ray]) -> u64 {
        let mut hits = 0;
        for r in rays {
            let missed = self.bvh.ray_traverse_miss(Self::ray(r), |ray, id| {
                self.tris[self.bvh.primitive_indices[id] as usize].intersect(ray)
            });
            hits += u64::from(!missed);
        }
        hits
    }
}

/// A triangle for the bvh crate: its points and its node index.
pub struct BvhTri {
    p: [nalgebra::Point3<f32>; 3],
    node: usize,
}

impl bvh::aabb::Bounded<f32, 3> for BvhTri {
    fn aabb(&self) -> bvh::aabb::Aabb<f32, 3> {
        bvh::aabb::Aabb::empty()
            .grow(&self.p[0])
            .grow(&self.p[1])
            .grow(&self.p[2])
    }
}

impl bvh::bounding_hierarchy::BHShape<f32, 3> for BvhTri {
    fn set_bh_node_index(&mut self, i: usize) {
        self.node = i;
    }
    fn bh_node_index(&self) -> usize {
        self.node
    }
}

/// bvh 0.13's tree over a triangle soup.
pub struct BvhScene {
    bvh: bvh::bvh::Bvh<f32, 3>,
    tris: Vec<BvhTri>,
}

impl BvhScene {
    /// Builds (one thread); returns the scene and the build's wall time.
    pub fn build(tris: &[[Vec3; 3]]) -> (Self, Duration) {
        let mut tris: Vec<BvhTri> = crate::peers::bvh_tris(tris)
            .into_iter()
            .map(|p| BvhTri { p, node: 0 })
            .collect();
        let start = Instant::now();
        let bvh = bvh::bvh::Bvh::build(&mut tris);
        (Self { bvh, tris }, start.elapsed())
    }

    /// Closest hit of every ray (back faces culled, as the crate does); returns the number of
    /// hits.
    pub fn closest(&self, rays: &[Ray]) -> u64 {
        let mut hits = 0;
        for r in rays {
            let ray = bvh::ray::Ray::new(
                crate::peers::bvh_point(r.origin),
                nalgebra::Vector3::new(r.dir.x, r.dir.y, r.dir.z),
            );
            let mut best = f32::INFINITY;
            for t in self.bvh.traverse(&ray, &self.tris) {
                let h = ray.intersects_triangle(&t.p[0], &t.p[1], &t.p[2]);
                if h.distance < best {
                    best = h.distance;
                }
            }
            hits += u64::from(best < f32::INFINITY);
        }
        hits
    }
}
