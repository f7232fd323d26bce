//! The packet crate's batch calls, by their own paths: every tier reachable at every width,
//! agreeing with the scalar twin; the scene calls agreeing with the slice calls; and the API
//! traps (lane bounds, length mismatches). In the suite's binary, whose walks they share.

use octoray_core::bvh::Bvh8;
use octoray_core::glam::Vec3;
use octoray_core::kernels::{
    Exact, ExactCulled, Kernel, MollerTrumbore, MollerTrumboreCulled, NaiveSphere, StableSphere,
    Watertight, WatertightCulled,
};
use octoray_core::lanes::Lanes;
use octoray_core::prim::{PackedSphere, PackedTriangle, Ray, RayLanes, VertexTriangle};
use octoray_core::query::ClosestHit;
use octoray_packet::{closest, closest_t, occluded, tree};
use octoray_packet::{f32x16, f32x4, f32x8, f64x4, f64x8};

fn rays() -> Vec<Ray> {
    // A fan of 37 rays (not a multiple of any width) from above a unit-ish grid of triangles.
    (0..37)
        .map(|i| {
            let x = (i % 7) as f32 * 0.31 - 0.2;
            let y = (i / 7) as f32 * 0.27 - 0.1;
            Ray::new(Vec3::new(x, y, 3.0), Vec3::new(0.05 * x, -0.02, -1.0))
        })
        .collect()
}

fn tris() -> Vec<[Vec3; 3]> {
    let mut t = vec![];
    for k in 0..12 {
        let (x, y, z) = (
            (k % 4) as f32 * 0.5 - 0.5,
            (k / 4) as f32 * 0.5 - 0.3,
            -(k as f32) * 0.1,
        );
        t.push([
            Vec3::new(x, y, z),
            Vec3::new(x + 0.6, y, z),
            Vec3::new(x, y + 0.6, z + 0.05),
        ]);
        t.push([
            Vec3::new(x, y, z - 1.0),
            Vec3::new(x, y + 0.6, z - 1.0),
            Vec3::new(x + 0.6, y, z - 1.0),
        ]);
    }
    t
}

/// The batch calls at width `L` agree with the scalar twin `S` (f32 or f64) ray by ray.
fn agrees<S: Lanes, L: Lanes, K, P>(prims: &[P]) -> usize
where
    K: Kernel<L, Prim = P> + Kernel<S, Prim = P>,
    P: octoray_core::prim::Primitive,
{
    let rays = rays();
    let mut out = vec![None; rays.len()];
    closest::<L, K>(&rays, prims, &mut out);
    let mut ts = vec![None; rays.len()];
    closest_t::<L, K>(&rays, prims, &mut ts);
    let mut occ = vec![false; rays.len()];
    occluded::<L, K>(&rays, prims, &mut occ);
    let mut hits = 0;
    for (i, r) in rays.iter().enumerate() {
        let twin = octoray_core::query::closest::<S, K>(&RayLanes::<S>::single(r), prims).lane(0);
        assert_eq!(out[i], twin, "ray {i}");
        assert_eq!(ts[i], twin.map(|h| h.t), "ray {i}");
        assert_eq!(occ[i], twin.is_some(), "ray {i}");
        hits += usize::from(twin.is_some());
    }
    hits
}

#[test]
fn every_tier_at_every_width_through_the_packet_crate() {
    let t = tris();
    let packed: Vec<PackedTriangle> = t
        .iter()
        .map(|v| PackedTriangle::new(v[0], v[1], v[2]))
        .collect();
    let verts: Vec<VertexTriangle> = t
        .iter()
        .map(|v| VertexTriangle::new(v[0], v[1], v[2]))
        .collect();
    let spheres: Vec<PackedSphere> = t.iter().map(|v| PackedSphere::new(v[0], 0.2)).collect();
    // Each tier at each width must find hits, or a broken tier would pass unnoticed.
    macro_rules! widths {
        ($k:ty, $p:expr) => {
            for (w, hits) in [
                ("f32x4", agrees::<f32, f32x4, $k, _>($p)),
                ("f32x8", agrees::<f32, f32x8, $k, _>($p)),
                ("f32x16", agrees::<f32, f32x16, $k, _>($p)),
                ("f64x4", agrees::<f64, f64x4, $k, _>($p)),
                ("f64x8", agrees::<f64, f64x8, $k, _>($p)),
            ] {
                assert!(
                    hits >= 8,
                    "{} at {w}: only {hits} of 37 rays hit",
                    stringify!($k)
                );
            }
        };
    }
    widths!(MollerTrumbore, &packed);
    widths!(MollerTrumboreCulled, &packed);
    widths!(Watertight, &verts);
    widths!(WatertightCulled, &verts);
    widths!(Exact, &verts);
    widths!(ExactCulled, &verts);
    widths!(StableSphere, &spheres);
    widths!(NaiveSphere, &spheres);
}

#[test]
fn scene_calls_equal_slice_calls() {
    let t = tris();
    let verts: Vec<VertexTriangle> = t
        .iter()
        .map(|v| VertexTriangle::new(v[0], v[1], v[2]))
        .collect();
    let bvh = Bvh8::build(&verts);
    let rays = rays();
    let (mut a, mut b) = (vec![None; rays.len()], vec![None; rays.len()]);
    closest::<f32x8, Watertight>(&rays, &verts, &mut a);
    tree::closest::<f32x8, Watertight>(bvh.as_ref(), &rays, &mut b);
    assert_eq!(a, b);
    let (mut a, mut b) = (vec![false; rays.len()], vec![false; rays.len()]);
    occluded::<f32x16, Watertight>(&rays, &verts, &mut a);
    tree::occluded::<f32x16, Watertight>(bvh.as_ref(), &rays, &mut b);
    assert_eq!(a, b);
    assert!(a.iter().any(|&x| x));
}

#[test]
fn lane_past_the_width_is_none_not_lane_zero() {
    // lane(32) of a one-lane result used to return lane 0's hit in release builds.
    let t = tris();
    let packed: Vec<PackedTriangle> = t
        .iter()
        .map(|v| PackedTriangle::new(v[0], v[1], v[2]))
        .collect();
    let r = rays()[0];
    let one: ClosestHit<f32> =
        octoray_core::query::closest::<f32, MollerTrumbore>(&RayLanes::single(&r), &packed);
    assert!(one.lane(0).is_some());
    for i in [1, 31, 32, 33, 64, usize::MAX] {
        assert_eq!(one.lane(i), None, "lane {i} of a one-lane result");
    }
    let eight =
        octoray_core::query::closest::<f32x8, MollerTrumbore>(&RayLanes::load(&[r; 8]), &packed);
    assert!(eight.lane(7).is_some());
    assert_eq!(eight.lane(8), None);
    assert_eq!(eight.lane(40), None);
}

#[test]
#[should_panic(expected = "octoray closest: 9 rays but 8 output entries")]
fn closest_with_a_short_output_panics() {
    let packed = [PackedTriangle::new(Vec3::ZERO, Vec3::X, Vec3::Y)];
    let mut out = [None; 8];
    closest::<f32x8, MollerTrumbore>(&[Ray::new(Vec3::Z, -Vec3::Z); 9], &packed, &mut out);
}

#[test]
#[should_panic(expected = "octoray occluded: 3 rays but 4 output entries")]
fn occluded_with_a_long_output_panics() {
    let packed = [PackedTriangle::new(Vec3::ZERO, Vec3::X, Vec3::Y)];
    let mut out = [false; 4];
    occluded::<f32x4, MollerTrumbore>(&[Ray::new(Vec3::Z, -Vec3::Z); 3], &packed, &mut out);
}

#[test]
#[should_panic(expected = "octoray closest_t: 2 rays but 0 output entries")]
fn closest_t_with_no_output_panics() {
    let packed = [PackedTriangle::new(Vec3::ZERO, Vec3::X, Vec3::Y)];
    closest_t::<f32x16, MollerTrumbore>(&[Ray::new(Vec3::Z, -Vec3::Z); 2], &packed, &mut []);
}

#[test]
fn ingest_errors_are_std_errors() {
    fn is_error<E: core::error::Error>(_: &E) {}
    let e = octoray_core::ingest::positions_from_flat(&[1.0, 2.0]).unwrap_err();
    is_error(&e);
    assert!(e.to_string().contains("triples"));
}
