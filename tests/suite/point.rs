//! Point and box queries: `tree::closest_point`, `tree::nearest_within` (k = 0, 1, 3, 8) and
//! `tree::overlapping` (paged three at a time) equal brute force over the primitives (the same
//! primitive, point and distance, bit for bit, ties to the lower index) on binned and
//! spatial-split trees of triangles (both layouts) and spheres, with and without a radius; and
//! the nearest point of one triangle is on the triangle and no farther than any point of it.
#![cfg(all(feature = "triangle", feature = "sphere"))]
use octoray::bvh::{BuildOptions, Bvh8, Sequential};
use octoray::glam::Vec3;
use octoray::kernels::{MeetsBox, Nearest, NearestPoint};
use octoray::prim::{PackedSphere, PackedTriangle, VertexTriangle};
use octoray::tree::{closest_point, nearest_within, overlapping, PointHit};
use octoray_testkit::cases::proptest_config;
use proptest::prelude::*;

/// Brute force: the nearest primitive within `max_dist` (ties to the lower index), as the tree
/// reports it.
fn brute<P: NearestPoint>(prims: &[P], p: Vec3, max_dist: f32) -> Option<PointHit> {
    let q = p.to_array().map(f64::from);
    let mut best: Option<(Nearest, u32)> = None;
    for (i, prim) in prims.iter().enumerate() {
        let n = prim.nearest(q);
        let limit = best.map_or(f64::from(max_dist) * f64::from(max_dist), |b| b.0.dist2);
        if n.dist2.is_finite() && (n.dist2 < limit || best.is_none() && n.dist2 <= limit) {
            best = Some((n, i as u32));
        }
    }
    best.map(|(n, prim)| PointHit {
        point: Vec3::from_array(n.point.map(|c| c as f32)),
        dist: n.dist2.sqrt() as f32,
        u: n.u as f32 + 0.0,
        v: n.v as f32 + 0.0,
        prim,
        ..PointHit::default()
    })
}

/// Brute force: every primitive within `r`, as the tree reports it, in order of distance, then
/// index.
fn brute_within<P: NearestPoint>(prims: &[P], p: Vec3, r: f32) -> Vec<PointHit> {
    let q = p.to_array().map(f64::from);
    let mut all: Vec<PointHit> = prims
        .iter()
        .enumerate()
        .filter_map(|(i, prim)| {
            let n = prim.nearest(q);
            (n.dist2.is_finite() && n.dist2 <= f64::from(r) * f64::from(r)).then(|| PointHit {
                point: Vec3::from_array(n.point.map(|c| c as f32)),
                dist: n.dist2.sqrt() as f32,
                u: n.u as f32 + 0.0,
                v: n.v as f32 + 0.0,
                prim: i as u32,
                ..PointHit::default()
            })
        })
        .collect();
    all.sort_by(|a, b| a.dist.total_cmp(&b.dist).then(a.prim.cmp(&b.prim)));
    all
}

fn check<P: NearestPoint>(
    prims: &[P],
    points: &[Vec3],
    radius: f32,
) -> Result<usize, TestCaseError> {
    let mut found = 0;
    for options in [BuildOptions::BINNED, BuildOptions::SPATIAL] {
        let bvh = Bvh8::try_build_options(prims, options, &Sequential).expect("build");
        for &p in points {
            for r in [f32::INFINITY, radius] {
                let got = closest_point(bvh.as_ref(), p, r);
                prop_assert_eq!(got, brute(prims, p, r), "{:?} within {}", p, r);
                found += got.is_some() as usize;
                for cap in [0, 1, 3, 8] {
                    let want = brute_within(prims, p, r);
                    let mut out = vec![PointHit::default(); cap];
                    let f = nearest_within(bvh.as_ref(), p, r, &mut out);
                    prop_assert_eq!(f.stored, want.len().min(cap));
                    prop_assert_eq!(f.complete, want.len() < cap || want.is_empty());
                    prop_assert_eq!(&out[..f.stored], &want[..f.stored], "{:?} within {}", p, r);
                }
            }
        }
    }
    Ok(found)
}

/// `overlapping` paged three at a time equals brute force on both tree kinds; returns it.
fn check_box<P: MeetsBox>(prims: &[P], lo: Vec3, hi: Vec3) -> Result<Vec<u32>, TestCaseError> {
    let (l, h) = (lo.to_array().map(f64::from), hi.to_array().map(f64::from));
    let want: Vec<u32> = (0..prims.len() as u32)
        .filter(|&i| prims[i as usize].meets(l, h))
        .collect();
    for options in [BuildOptions::BINNED, BuildOptions::SPATIAL] {
        let bvh = Bvh8::try_build_options(prims, options, &Sequential).expect("build");
        let (mut got, mut page, mut after) = (vec![], [0u32; 3], None);
        loop {
            let f = overlapping(bvh.as_ref(), lo, hi, after, &mut page);
            got.extend_from_slice(&page[..f.stored]);
            if f.complete {
                break;
            }
            after = Some(page[f.stored - 1]);
        }
        prop_assert_eq!(&got, &want, "{:?}..{:?}", lo, hi);
    }
    Ok(want)
}

/// A triangle with a vertex in the box meets it; one whose bounds miss the box does not.
fn vertex_sanity(
    tris: &[[Vec3; 3]],
    lo: Vec3,
    hi: Vec3,
    found: &[u32],
) -> Result<(), TestCaseError> {
    for (i, v) in tris.iter().enumerate() {
        let inside = v.iter().any(|&q| q.cmpge(lo).all() && q.cmple(hi).all());
        let (bl, bh) = (v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]));
        let apart = bl.cmpgt(hi).any() || bh.cmplt(lo).any();
        let listed = found.contains(&(i as u32));
        prop_assert!(!inside || listed, "vertex inside, {}", i);
        prop_assert!(!apart || !listed, "bounds apart, {}", i);
    }
    Ok(())
}

fn point() -> impl Strategy<Value = Vec3> {
    prop::array::uniform3(-12.0f32..12.0).prop_map(Vec3::from_array)
}

/// Coordinates on a coarse grid half the time: equal distances (ties) and points on edges.
fn coord() -> impl Strategy<Value = f32> {
    prop_oneof![-8.0f32..8.0, (-8i32..8).prop_map(|x| x as f32)]
}

fn corner() -> impl Strategy<Value = Vec3> {
    prop::array::uniform3(coord()).prop_map(Vec3::from_array)
}

proptest! {
    #![proptest_config(proptest_config(64))]

    #[test]
    fn closest_point_equals_brute_force(
        tris in prop::collection::vec(prop::array::uniform3(corner()), 1..120),
        balls in prop::collection::vec((corner(), 0.01f32..3.0), 1..60),
        points in prop::collection::vec(prop_oneof![point(), corner()], 24),
        radius in 0.0f32..4.0,
    ) {
        let vt: Vec<VertexTriangle> = tris.iter().map(|t| VertexTriangle::new(t[0], t[1], t[2])).collect();
        let pt: Vec<PackedTriangle> = tris.iter().map(|t| PackedTriangle::new(t[0], t[1], t[2])).collect();
        let sp: Vec<PackedSphere> = balls.iter().map(|&(c, r)| PackedSphere::new(c, r)).collect();
        check(&vt, &points, radius)?;
        check(&pt, &points, radius)?;
        check(&sp, &points, radius)?;
        for (i, &p) in points.iter().enumerate().take(6) {
            let half = Vec3::splat(radius * 0.5) * Vec3::new(1.0, 0.5 + (i % 3) as f32, 1.0);
            let (lo, hi) = (p - half, p + half);
            let found = check_box(&vt, lo, hi)?;
            vertex_sanity(&tris, lo, hi, &found)?;
            check_box(&pt, lo, hi)?;
            check_box(&sp, lo, hi)?;
        }
    }

    #[test]
    fn closest_point_equals_brute_force_on_and_near_the_planes_far_out(
        tris in prop::collection::vec(prop::array::uniform3(prop::array::uniform3(-2.0f32..2.0)), 1..60),
        offset in prop::array::uniform3(prop_oneof![Just(0.0f32), -3e4f32..3e4]),
        picks in prop::collection::vec((0usize..60, 0.0f32..1.0, 0.0f32..1.0, -3i32..=3), 24),
        squash in prop_oneof![Just(1.0f32), Just(1e-3f32), Just(1e-6f32)],
    ) {
        // Triangles (flattened along z by `squash`: thin and nearly coplanar ones) moved far
        // out, and points on their planes or a few ulps to hundreds of ulps off them: where
        // the plane bound's slack decides what is culled.
        let o = Vec3::from_array(offset);
        let tris: Vec<[Vec3; 3]> = tris
            .iter()
            .map(|t| t.map(|v| o + Vec3::new(v[0], v[1], v[2] * squash)))
            .collect();
        let vt: Vec<VertexTriangle> = tris.iter().map(|t| VertexTriangle::new(t[0], t[1], t[2])).collect();
        let points: Vec<Vec3> = picks
            .iter()
            .map(|&(i, a, b, k)| {
                let t = &tris[i % tris.len()];
                let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
                let on = t[0] + (t[1] - t[0]) * a + (t[2] - t[0]) * b;
                let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
                on + n * (k as f32) * on.abs().max_element().max(1.0) * f32::EPSILON * 16f32.powi(k.abs())
            })
            .collect();
        check(&vt, &points, 0.5)?;
    }

    #[test]
    fn the_nearest_point_is_on_the_triangle_and_nearest(
        t in prop::array::uniform3(corner()),
        p in point(),
        samples in prop::collection::vec((0.0f64..1.0, 0.0f64..1.0), 32),
    ) {
        let tri = VertexTriangle::new(t[0], t[1], t[2]);
        let q = p.to_array().map(f64::from);
        let n = tri.nearest(q);
        let v = [t[0], t[1], t[2]].map(|x| x.to_array().map(f64::from));
        let at = |u: f64, w: f64| -> [f64; 3] {
            core::array::from_fn(|k| v[0][k] + u * (v[1][k] - v[0][k]) + w * (v[2][k] - v[0][k]))
        };
        let dist2 = |x: [f64; 3]| (0..3).map(|k| (x[k] - q[k]).powi(2)).sum::<f64>();
        let scale = v.iter().flatten().chain(&q).fold(1.0f64, |m, x| m.max(x.abs()));
        let tol = 1e-12 * scale * scale;
        // On the triangle: barycentrics in range, the point where they say.
        prop_assert!(n.u >= 0.0 && n.v >= 0.0 && n.u + n.v <= 1.0 + 1e-12, "{:?}", n);
        let there = at(n.u, n.v);
        prop_assert!(dist2(there).sqrt() - n.dist2.sqrt() <= 1e-9 * scale, "{:?} vs {:?}", n, there);
        prop_assert!((dist2(n.point) - n.dist2).abs() <= tol, "{:?}", n);
        // No point of the triangle is nearer: the vertices, the edges' midpoints, samples.
        let mut pts = vec![at(0.0, 0.0), at(1.0, 0.0), at(0.0, 1.0), at(0.5, 0.0), at(0.0, 0.5), at(0.5, 0.5)];
        pts.extend(samples.iter().map(|&(a, b)| if a + b <= 1.0 { at(a, b) } else { at(1.0 - a, 1.0 - b) }));
        for x in pts {
            prop_assert!(n.dist2 <= dist2(x) + tol, "{:?} beats {:?}", x, n);
        }
    }
}

#[test]
fn bad_points_and_radii_find_nothing() {
    let tris = [VertexTriangle::new(Vec3::ZERO, Vec3::X, Vec3::Y)];
    let bvh = Bvh8::build(&tris);
    let b = bvh.as_ref();
    for p in [Vec3::NAN, Vec3::new(0.0, f32::INFINITY, 0.0)] {
        assert_eq!(closest_point(b, p, f32::INFINITY), None);
    }
    for r in [f32::NAN, -1.0, f32::NEG_INFINITY] {
        assert_eq!(closest_point(b, Vec3::ZERO, r), None);
    }
    // The radius is inclusive: a point at exactly distance 1.
    let hit = closest_point(b, Vec3::new(0.0, 0.0, 1.0), 1.0).unwrap();
    assert_eq!((hit.dist, hit.point, hit.prim), (1.0, Vec3::ZERO, 0));
    let empty = Bvh8::<VertexTriangle>::build(&[]);
    assert_eq!(
        closest_point(empty.as_ref(), Vec3::ZERO, f32::INFINITY),
        None
    );
    // A sphere that is never hit (radius 0) is never nearest.
    let balls = [
        PackedSphere::new(Vec3::ZERO, 0.0),
        PackedSphere::new(Vec3::X * 5.0, 1.0),
    ];
    let sb = Bvh8::build(&balls);
    assert_eq!(
        closest_point(sb.as_ref(), Vec3::ZERO, f32::INFINITY).map(|h| (h.prim, h.dist)),
        Some((1, 4.0))
    );
}

/// A fan of triangles around one vertex, each in its own corner of space: a point over the
/// vertex is equally near all of them, and the lowest index wins however the tree orders them.
#[test]
fn equal_distances_go_to_the_lowest_index() {
    for rot in 0..24 {
        let tris: Vec<VertexTriangle> = (0..48)
            .map(|i| {
                let a = ((i + rot) % 48) as f32 * std::f32::consts::TAU / 48.0;
                let b = a + 0.1;
                let far = 40.0 + (i % 5) as f32;
                VertexTriangle::new(
                    Vec3::ZERO,
                    Vec3::new(a.cos(), a.sin(), 0.0) * far,
                    Vec3::new(b.cos(), b.sin(), 0.0) * far,
                )
            })
            .collect();
        let bvh = Bvh8::build(&tris);
        for z in [1.0, -3.0, 0.25] {
            let hit = closest_point(bvh.as_ref(), Vec3::new(0.0, 0.0, z), f32::INFINITY).unwrap();
            assert_eq!(
                (hit.prim, hit.point, hit.dist),
                (0, Vec3::ZERO, z.abs()),
                "rotation {rot}"
            );
        }
    }
}
