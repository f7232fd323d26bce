//! Query kinds compute only what is asked and agree, bit for bit, with the full closest-hit query
//! on what they share; back-face culling drops exactly the back faces; surface data faces the ray
//! and its spawn points do not re-hit.
#![cfg(all(feature = "triangle", feature = "sphere"))]

mod common;

use common::Rng;
use octoray::core::kernel::{
    Kernel, StableSphere, Standard, StandardCulled, Watertight, WatertightCulled,
};
use octoray::core::query::{any_hit, closest_hit, closest_t};
use octoray::core::surface::{packed_triangle_surface, vertex_triangle_surface};
use octoray::core::{LaneMask, Lanes, RayLanes, Scalar};
use octoray::glam::Vec3;
use octoray::packet::{f32x16, f32x8};
use octoray::{PackedSphere, PackedTriangle, Ray, VertexTriangle};

fn scene(seed: u64) -> (Vec<Ray>, Vec<[Vec3; 3]>) {
    let mut rng = Rng(seed);
    let tris: Vec<[Vec3; 3]> = (0..48)
        .map(|_| {
            let c = rng.vec3(2.0);
            [c + rng.vec3(0.7), c + rng.vec3(0.7), c + rng.vec3(0.7)]
        })
        .collect();
    let rays = (0..200)
        .map(|_| {
            let o = rng.vec3(4.0);
            Ray::new(o, rng.vec3(1.5) - o)
        })
        .collect();
    (rays, tris)
}

fn kinds_agree<L: Lanes, K: Kernel<L>>(rays: &[Ray], prims: &[K::Prim]) {
    for c in rays.chunks(L::LANES) {
        let p = RayLanes::<L>::load(c);
        let full = closest_hit::<L, K>(&p, prims);
        let (mask, t) = closest_t::<L, K>(&p, prims);
        let any = any_hit::<L, K>(&p, prims);
        assert_eq!(mask.bitmask(), full.mask.bitmask());
        assert_eq!(any.bitmask(), full.mask.bitmask());
        for i in 0..c.len() {
            if let Some(h) = full.lane(i) {
                assert_eq!(
                    t.lane(i).to_f64().to_bits(),
                    f64::from(h.t).to_bits(),
                    "closest-t lane {i}"
                );
            }
        }
    }
}

#[test]
fn every_query_kind_agrees_with_closest_hit() {
    let (rays, tris) = scene(1);
    let packed: Vec<PackedTriangle> = tris
        .iter()
        .map(|t| PackedTriangle::new(t[0], t[1], t[2]))
        .collect();
    let verts: Vec<VertexTriangle> = tris
        .iter()
        .map(|t| VertexTriangle::new(t[0], t[1], t[2]))
        .collect();
    let spheres: Vec<PackedSphere> = tris.iter().map(|t| PackedSphere::new(t[0], 0.3)).collect();
    kinds_agree::<f32, Standard>(&rays, &packed);
    kinds_agree::<f32x8, Standard>(&rays, &packed);
    kinds_agree::<f32x16, Standard>(&rays, &packed);
    kinds_agree::<f32x8, Watertight>(&rays, &verts);
    kinds_agree::<f32x8, StandardCulled>(&rays, &packed);
    kinds_agree::<f32x8, StableSphere>(&rays, &spheres);
}

#[test]
fn culling_drops_exactly_the_back_faces() {
    let (rays, tris) = scene(2);
    let (mut front, mut back) = (0, 0);
    for r in &rays {
        for t in &tris {
            let n = (t[1] - t[0]).cross(t[2] - t[0]);
            let packed = [PackedTriangle::new(t[0], t[1], t[2])];
            let verts = [VertexTriangle::new(t[0], t[1], t[2])];
            let p = RayLanes::<f32>::single(r);
            let both = closest_hit::<f32, Standard>(&p, &packed).lane(0);
            let culled = closest_hit::<f32, StandardCulled>(&p, &packed).lane(0);
            let wt_both = closest_hit::<f32, Watertight>(&p, &verts).lane(0);
            let wt_culled = closest_hit::<f32, WatertightCulled>(&p, &verts).lane(0);
            // A front face's normal points against the ray.
            let is_front = n.dot(r.dir) < 0.0;
            if both.is_some() {
                if is_front {
                    front += 1;
                    assert_eq!(culled, both, "front face culled");
                } else {
                    back += 1;
                    assert_eq!(culled, None, "back face kept");
                }
            }
            if wt_both.is_some() {
                assert_eq!(
                    wt_culled.is_some(),
                    is_front,
                    "watertight culling: front {is_front}"
                );
            }
        }
    }
    assert!(front > 20 && back > 20, "front {front} back {back}");
}

trait With: Sized {
    fn with(self, h: octoray::Hit) -> (Self, octoray::Hit) {
        (self, h)
    }
}
impl With for octoray::core::surface::Surface {}

#[test]
fn surface_data_faces_the_ray_and_spawns_without_rehits() {
    let (rays, tris) = scene(3);
    let mut checked = 0;
    for r in &rays {
        for t in &tris {
            let packed = PackedTriangle::new(t[0], t[1], t[2]);
            let verts = VertexTriangle::new(t[0], t[1], t[2]);
            let standard = octoray::core::intersect::<f32, Standard>(r, &packed)
                .map(|h| packed_triangle_surface(r, &packed, &h).with(h));
            let watertight = octoray::core::intersect::<f32, Watertight>(r, &verts)
                .map(|h| vertex_triangle_surface(r, &verts, &h).with(h));
            for (s, hit) in standard.into_iter().chain(watertight) {
                assert!(s.normal.dot(r.dir) <= 0.0 && (s.normal.length() - 1.0).abs() < 1e-5);
                assert!((s.point - r.at(hit.t)).length() < 1e-4);
                for (origin, dir) in [(s.spawn_front, s.normal), (s.spawn_back, -s.normal)] {
                    let spawn = Ray::new(origin, dir);
                    assert_eq!(
                        octoray::core::intersect::<f32, Standard>(&spawn, &packed),
                        None
                    );
                    assert_eq!(
                        octoray::core::intersect::<f32, Watertight>(&spawn, &verts),
                        None
                    );
                }
                checked += 1;
            }
        }
    }
    assert!(checked > 100, "{checked}");
}
