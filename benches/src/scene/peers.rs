//! The scene-level peers, each built and traversed the way its documentation shows, on the same
//! triangles and rays as octoray's rows:
//!
//! - [`ObvhsScene`]: obvhs 0.4's CWBVH (`build_cwbvh_from_tris` with `medium_build`) and its own
//!   traversal (`ray_traverse`, `ray_traverse_miss`) with `Triangle::intersect`.
//! - [`BvhScene`]: bvh 0.13 (`Bvh::build`, `traverse` for the candidates, then
//!   `Ray::intersects_triangle`, which culls back faces).
//! - [`crate::scene::embree`]: Embree 3 through its C API, loaded at run time.
//! - [`TinyBvhScene`]: tinybvh 1.6.8's `BVH8_CPU` through `tinybvh-rs` (the `tinybvh` feature).

use crate::scene::row::{Query, Traversal};
use crate::scene::trace::Traces;
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
        let tris = crate::kernel::peers::obvhs_tris(tris);
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
        let mut tris: Vec<BvhTri> = crate::kernel::peers::bvh_tris(tris)
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
                crate::kernel::peers::bvh_point(r.origin),
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

/// tinybvh 1.6.8's `BVH8_CPU` (through `tinybvh-rs`): its fastest CPU single-ray layout (AVX2
/// leaves of 4 triangles, Möller-Trumbore with an approximate `1/det`; not watertight), built
/// from its binned SAH build (`BVH::Build`) or its spatial-split build (`BVH::BuildHQ`), leaves
/// split to 4 and converted through `MBVH8`. Closest hit only: the wrapper has no occlusion
/// query. Only with the benches' `tinybvh` feature (a C++ compiler) on an AVX2 build.
pub struct TinyBvhScene {
    #[cfg(all(feature = "tinybvh", target_feature = "avx2"))]
    bvh: tinybvh_rs::bvh8_cpu::BVH,
}

impl TinyBvhScene {
    /// Builds (`hq`: with spatial splits) on one thread; returns the scene and the wall time of
    /// the whole build (the binary tree, the leaf split and both conversions), or why the peer
    /// is skipped.
    #[cfg(all(feature = "tinybvh", target_feature = "avx2"))]
    pub fn build(tris: &[[Vec3; 3]], hq: bool) -> Result<(Self, Duration), String> {
        use tinybvh_rs::{bvh, bvh8_cpu, mbvh};
        let verts: Vec<[f32; 4]> = tris
            .iter()
            .flat_map(|t| t.map(|v| [v.x, v.y, v.z, 0.0]))
            .collect();
        let start = Instant::now();
        let positions: tinybvh_rs::Positions<'_> = verts.as_slice().into();
        let mut binary = if hq {
            bvh::BVH::new_hq(positions)
        } else {
            bvh::BVH::new(positions)
        }
        .map_err(|e| e.to_string())?;
        binary.split_leaves(4);
        let wide = mbvh::BVH::new(&binary);
        let bvh = bvh8_cpu::BVH::new(&wide).map_err(|e| e.to_string())?;
        Ok((Self { bvh }, start.elapsed()))
    }

    /// Without the `tinybvh` feature or AVX2: why the rows are skipped.
    #[cfg(not(all(feature = "tinybvh", target_feature = "avx2")))]
    pub fn build(_: &[[Vec3; 3]], _: bool) -> Result<(Self, Duration), String> {
        Err(if cfg!(feature = "tinybvh") {
            "tinybvh's BVH8_CPU walk needs an AVX2 build (RUSTFLAGS=\"-C target-cpu=native\")"
                .into()
        } else {
            "build the benches with `--features tinybvh` (needs a C++20 compiler)".into()
        })
    }

    /// Closest hit of every ray (a positive `t_min` is applied by moving the origin: tinybvh's
    /// rays start at 0); returns the number of hits.
    ///
    /// The wrapper's `Ray` is 64 bytes where tinybvh 1.6.8's C++ `Ray` is 128 (its hit record
    /// carries 64 bytes of user data), so `Ray::new`, which returns the C++ object by value,
    /// writes past the Rust one (a segmentation fault on Sponza). The first 64 bytes agree field
    /// for field (the `padding_*` words are the C++ `mask`, `instIdx` and `hit.inst`), so the ray
    /// is built here field by field, as the C++ constructor does without normalising the
    /// direction (`t` then stays in the caller's units), inside a 128-byte block that holds
    /// what the C++ side may touch.
    #[cfg(all(feature = "tinybvh", target_feature = "avx2"))]
    pub fn closest(&self, rays: &[Ray]) -> u64 {
        use tinybvh_rs::Intersector;
        /// Room for the C++ `Ray` (128 bytes, 64-aligned) around the wrapper's first 64.
        #[repr(C, align(64))]
        struct Whole {
            ray: tinybvh_rs::Ray,
            rest: [u32; 16],
        }
        // tinybvh_safercp: 1/x, or ±1e30 for |x| ≤ 1e-12.
        let rcp = |x: f32| {
            if x.abs() > 1e-12 {
                1.0 / x
            } else if x >= 0.0 {
                tinybvh_rs::INFINITE
            } else {
                -tinybvh_rs::INFINITE
            }
        };
        let mut hits = 0;
        for r in rays {
            let o = r.origin + r.dir * r.t_min;
            let far = (r.t_max - r.t_min).min(tinybvh_rs::INFINITE);
            let mut w = Whole {
                ray: tinybvh_rs::Ray {
                    origin: o.into(),
                    padding_0: 0xffff,
                    dir: r.dir.into(),
                    padding_1: 0,
                    r_d: r.dir.to_array().map(rcp),
                    padding_2: 0,
                    hit: tinybvh_rs::Intersection {
                        t: far,
                        ..Default::default()
                    },
                },
                rest: [0; 16],
            };
            self.bvh.intersect(&mut w.ray);
            hits += u64::from(w.ray.hit.t < far);
        }
        hits
    }

    /// Never called: [`TinyBvhScene::build`] fails without the peer.
    #[cfg(not(all(feature = "tinybvh", target_feature = "avx2")))]
    pub fn closest(&self, _: &[Ray]) -> u64 {
        0
    }
}

impl Traces for ObvhsScene {
    fn trace(&self, query: Query, traversal: Traversal, rays: &[Ray]) -> Option<u64> {
        match (query, traversal) {
            (Query::Closest, Traversal::Single) => Some(self.closest(rays)),
            (Query::Any, Traversal::Single) => Some(self.any(rays)),
            _ => None,
        }
    }
}

impl Traces for BvhScene {
    fn trace(&self, query: Query, traversal: Traversal, rays: &[Ray]) -> Option<u64> {
        match (query, traversal) {
            (Query::Closest, Traversal::Single) => Some(self.closest(rays)),
            _ => None,
        }
    }
}

impl Traces for TinyBvhScene {
    /// The wrapper has no occlusion query: [`Query::Any`] is its closest hit within the segment.
    fn trace(&self, _: Query, traversal: Traversal, rays: &[Ray]) -> Option<u64> {
        (traversal == Traversal::Single).then(|| self.closest(rays))
    }
}
