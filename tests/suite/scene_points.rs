//! Point queries on scenes (`Trace::closest_point`, `Trace::nearest_within`) equal brute force
//! over the instanced primitives bit for bit: the random worlds of the scene suite (rotations,
//! non-uniform, mirrored and sheared scales, nearly singular and raw maps, groups, masks, spheres
//! that become ellipsoids), each primitive measured in world space with the same maps.
#![cfg(all(feature = "triangle", feature = "sphere", feature = "alloc"))]

use super::scene::{overlapping_world, pack_vertex, world, Geom, Place, Target, World};
use octoray::glam::{Affine3A, Vec3};
use octoray::kernels::{MeetsBox, Nearest, NearestPoint};
use octoray::prim::{Affine64, PackedSphere, VertexTriangle};
use octoray::scene::{Scene, Trace, Transform};
use octoray::tree::PointHit;
use octoray_testkit::Rng;
use proptest::prelude::*;

/// A candidate: its squared distance, where it lies (instance path, geometry, primitive) and
/// its answer.
type Found = (f64, (u32, u32, u32), Nearest);

/// Each of `prims` measured from `p`: as it is, or placed by `map`.
fn measured<P: NearestPoint>(prims: &[P], map: Option<&Affine64>, p: [f64; 3]) -> Vec<Nearest> {
    let one = |x: &P| map.map_or_else(|| x.nearest(p), |m| x.nearest_mapped(m, p));
    prims.iter().map(one).collect()
}

/// Every admitted primitive of `places` (a level whose space maps to the world by `to_world`)
/// measured from the world point `p`; `path` counts instance paths depth first, also through
/// instances left out.
fn brute_level(
    w: &World<VertexTriangle>,
    places: &[Place],
    to_world: Option<Affine64>,
    p: [f64; 3],
    mask: u32,
    path: &mut u32,
    out: &mut Vec<Found>,
) {
    for inst in places {
        // As the walk composes them: the instance's inverse, then the level's map to the world.
        let here = to_world.and_then(|tw| Some(inst.transform.to_f64().inverse()?.then(&tw)));
        let geoms = match &inst.target {
            Target::Group(g) => {
                let m = mask & inst.mask;
                brute_level(w, &w.groups[*g], here, p, m, path, out);
                continue;
            }
            Target::Geoms(geoms) => geoms,
        };
        for &geom in geoms {
            let (g, gmask) = &w.geoms[geom as usize];
            let Some(map) = here.filter(|_| inst.mask & gmask & mask != 0) else {
                continue;
            };
            // As the walk measures: directly where the map is the identity.
            let placed = (map != Affine64::IDENTITY).then_some(&map);
            let ns = match g {
                Geom::Tris(ts) => measured(ts, placed, p),
                Geom::Spheres(ss) => measured(ss, placed, p),
            };
            let place = |i: usize| (*path, geom, i as u32);
            out.extend(
                ns.into_iter()
                    .enumerate()
                    .map(|(i, n)| (n.dist2, place(i), n)),
            );
        }
        *path += 1;
    }
}

/// A candidate as the queries report it.
fn reported((_, (inst, geom, prim), n): Found) -> PointHit {
    PointHit {
        point: Vec3::from_array(n.point.map(|x| x as f32)),
        dist: n.dist2.sqrt() as f32,
        u: n.u as f32 + 0.0,
        v: n.v as f32 + 0.0,
        prim,
        geom,
        inst,
    }
}

/// Brute force's candidates within `radius` of `p` under `mask`.
fn within(w: &World<VertexTriangle>, p: Vec3, radius: f32, mask: u32) -> Vec<Found> {
    let mut all = Vec::new();
    let pf = p.to_array().map(f64::from);
    let world = Some(Affine64::IDENTITY);
    brute_level(w, &w.insts, world, pf, mask, &mut 0, &mut all);
    let r2 = f64::from(radius) * f64::from(radius);
    all.retain(|f| f.0.is_finite() && f.0 <= r2);
    all
}

/// Brute force's answers as the queries report them, nearest first (ties by place), within
/// `radius`.
fn brute(w: &World<VertexTriangle>, p: Vec3, radius: f32, mask: u32) -> Vec<PointHit> {
    let mut hits: Vec<PointHit> = within(w, p, radius, mask)
        .into_iter()
        .map(reported)
        .collect();
    hits.sort_by(|a, b| {
        a.dist
            .total_cmp(&b.dist)
            .then((a.inst, a.geom, a.prim).cmp(&(b.inst, b.geom, b.prim)))
    });
    hits
}

/// The nearest by exact squared distance (what `closest_point` ranks by), ties by place.
fn brute_closest(w: &World<VertexTriangle>, p: Vec3, radius: f32, mask: u32) -> Option<PointHit> {
    within(w, p, radius, mask)
        .into_iter()
        .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
        .map(reported)
}

/// Query points: near the world's primitives (the rays' origins and points along them), far
/// away, and a non-finite one.
fn points(rng: &mut Rng, rays: &[octoray::prim::Ray]) -> Vec<Vec3> {
    let mut out: Vec<Vec3> = rays
        .iter()
        .filter(|r| r.dir.is_finite())
        .take(24)
        .map(|r| r.origin + r.dir * rng.range(0.0, 1.2))
        .filter(|p| p.is_finite())
        .collect();
    out.push(Vec3::splat(1e6));
    out.push(Vec3::new(f32::NAN, 0.0, 0.0));
    out
}

fn case(seed: u64) -> usize {
    let (w, rays) = world(seed, pack_vertex);
    case_on(seed, &w, &rays)
}

/// The point queries of world `w` at points near `rays`, checked against brute force; returns
/// how many closest points were found.
fn case_on(seed: u64, w: &World<VertexTriangle>, rays: &[octoray::prim::Ray]) -> usize {
    let scene = w.scene();
    let r = scene.as_ref();
    let mut rng = Rng(seed ^ 0x51);
    let mut found = 0;
    for p in points(&mut rng, rays) {
        for (mask, radius) in [(!0, f32::INFINITY), (1, f32::INFINITY), (!0, 0.5)] {
            let want = brute_closest(w, p, radius, mask);
            let got = r.closest_point(p, radius, mask);
            assert_eq!(
                got,
                want.filter(|_| p.is_finite()),
                "seed {seed}: {p} mask {mask}"
            );
            found += got.is_some() as usize;
            let all = brute(w, p, radius, mask);
            for k in [0, 1, 4] {
                let mut out = vec![PointHit::default(); k];
                let f = r.nearest_within(p, radius, mask, &mut out);
                let want: Vec<_> = if p.is_finite() {
                    all.iter().take(k).copied().collect()
                } else {
                    vec![]
                };
                assert_eq!(&out[..f.stored], &want[..], "seed {seed}: {p} k {k}");
                assert_eq!(
                    f.complete,
                    !p.is_finite() || all.len() < k || all.is_empty()
                );
            }
        }
    }
    found
}

/// Brute force's box query: every admitted primitive of `places` (a level whose maps to and
/// from the world are `maps`, composed as the walk composes them) tested in world space, where
/// each lies, sorted.
fn brute_boxes(
    w: &World<VertexTriangle>,
    places: &[Place],
    maps: (Affine64, Affine64),
    (lo, hi): ([f64; 3], [f64; 3]),
    mask: u32,
    path: &mut u32,
    out: &mut Vec<(u32, u32, u32)>,
) {
    for inst in places {
        let a = inst.transform.to_f64();
        let here = a.inverse().map(|inv| (inv.then(&maps.0), maps.1.then(&a)));
        let geoms = match &inst.target {
            Target::Group(g) => {
                if let Some(m) = here {
                    brute_boxes(w, &w.groups[*g], m, (lo, hi), mask & inst.mask, path, out);
                } else {
                    // Left out, its paths still counted.
                    let (i, o) = (Affine64::IDENTITY, Affine64::IDENTITY);
                    let mut none = Vec::new();
                    brute_boxes(w, &w.groups[*g], (i, o), (lo, hi), 0, path, &mut none);
                }
                continue;
            }
            Target::Geoms(geoms) => geoms,
        };
        for &geom in geoms {
            let (g, gmask) = &w.geoms[geom as usize];
            let Some((to_world, to_here)) = here.filter(|_| inst.mask & gmask & mask != 0) else {
                continue;
            };
            let identity = to_world == Affine64::IDENTITY;
            let meets = |m: &dyn Fn() -> bool, plain: &dyn Fn() -> bool| {
                if identity {
                    plain()
                } else {
                    m()
                }
            };
            let n = match g {
                Geom::Tris(ts) => ts.len(),
                Geom::Spheres(ss) => ss.len(),
            };
            for i in 0..n {
                let hit = match g {
                    Geom::Tris(ts) => {
                        meets(&|| ts[i].meets_mapped(&to_world, &to_here, lo, hi), &|| {
                            ts[i].meets(lo, hi)
                        })
                    }
                    Geom::Spheres(ss) => {
                        meets(&|| ss[i].meets_mapped(&to_world, &to_here, lo, hi), &|| {
                            ss[i].meets(lo, hi)
                        })
                    }
                };
                if hit {
                    out.push((*path, geom, i as u32));
                }
            }
        }
        *path += 1;
    }
}

/// The scene's box query, paged, against brute force; returns how many it found.
fn check_boxes(
    w: &World<VertexTriangle>,
    r: octoray::scene::SceneRef<'_, VertexTriangle, PackedSphere>,
    lo: Vec3,
    hi: Vec3,
    mask: u32,
) -> usize {
    let mut want = Vec::new();
    let b = (lo.to_array().map(f64::from), hi.to_array().map(f64::from));
    let id = (Affine64::IDENTITY, Affine64::IDENTITY);
    if lo.cmple(hi).all() {
        brute_boxes(w, &w.insts, id, b, mask, &mut 0, &mut want);
    }
    want.sort();
    want.dedup();
    // Pages of three where the answer is short, larger ones where it is long (each page walks
    // the scene again).
    let size = if want.len() <= 30 { 3 } else { 512 };
    let mut page = vec![octoray::scene::Place::default(); size];
    let (mut got, mut after) = (vec![], None);
    loop {
        let f = r.overlapping(lo, hi, mask, after, &mut page);
        got.extend(page[..f.stored].iter().map(|p| (p.inst, p.geom, p.prim)));
        if f.complete {
            break;
        }
        after = Some(page[f.stored - 1]);
    }
    assert_eq!(got, want, "box {lo}..{hi} mask {mask}");
    got.len()
}

/// Boxes around points near the world's primitives, of sizes from a speck to the world's.
fn boxes_case(seed: u64, w: &World<VertexTriangle>, rays: &[octoray::prim::Ray]) -> usize {
    let scene = w.scene();
    let mut rng = Rng(seed ^ 0xB0);
    let mut found = 0;
    for p in points(&mut rng, rays).into_iter().take(12) {
        let half = Vec3::new(
            rng.range(0.0, 1.0),
            rng.range(0.0, 1.0),
            rng.range(0.0, 1.0),
        ) * 10f32.powf(rng.range(-3.0, 1.5));
        for mask in [!0, 1] {
            found += check_boxes(w, scene.as_ref(), p - half, p + half, mask);
        }
    }
    found
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn scene_box_queries_equal_brute_force_over_instanced_primitives(seed in any::<u64>()) {
        let (w, rays) = world(seed, pack_vertex);
        boxes_case(seed, &w, &rays);
    }
}

#[test]
fn many_scene_boxes_find_primitives() {
    let found: usize = (0..12)
        .map(|s| {
            let (w, rays) = world(s * 7919, pack_vertex);
            boxes_case(s, &w, &rays)
        })
        .sum();
    let overlapping: usize = (0..3)
        .map(|s| {
            let (w, rays) = overlapping_world(s);
            boxes_case(s, &w, &rays)
        })
        .sum();
    assert!(
        found > 300 && overlapping > 100,
        "only {found} / {overlapping} found"
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn scene_point_queries_equal_brute_force_over_instanced_primitives(seed in any::<u64>()) {
        case(seed);
    }
}

#[test]
fn many_scene_points_are_found() {
    let found: usize = (0..12).map(|s| case(s * 104_729)).sum();
    assert!(
        found > 300,
        "only {found} answers: the suite would not test much"
    );
}

/// Overlapping instances entered by parts (partial re-braiding) answer as brute force.
#[test]
fn overlapping_instances_answer_as_brute_force() {
    let found: usize = (0..4)
        .map(|seed| {
            let (w, rays) = overlapping_world(seed);
            case_on(seed, &w, &rays)
        })
        .sum();
    assert!(found > 60, "only {found} answers");
}

/// A sphere squashed into an ellipsoid by its instance, and a triangle mesh moved and scaled:
/// the answers are in world space.
#[test]
fn instances_answer_in_world_space() {
    let mut s = Scene::<VertexTriangle, PackedSphere>::new();
    let ball = s
        .add_spheres(&[PackedSphere::new(Vec3::ZERO, 1.0)])
        .unwrap();
    let tri = s
        .add_triangles(&[VertexTriangle::new(
            Vec3::ZERO,
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        )])
        .unwrap();
    // The ball stretched to semi-axes (4, 1, 1) at x = 10; the triangle scaled by 2 at z = -5.
    let squash = Affine3A::from_scale_rotation_translation(
        Vec3::new(4.0, 1.0, 1.0),
        Default::default(),
        Vec3::new(10.0, 0.0, 0.0),
    );
    s.add_instance(&[ball], Transform::placing(squash).unwrap(), !0);
    let moved = Affine3A::from_scale_rotation_translation(
        Vec3::splat(2.0),
        Default::default(),
        Vec3::new(0.0, 0.0, -5.0),
    );
    s.add_instance(&[tri], Transform::placing(moved).unwrap(), !0);
    s.commit().unwrap();
    let r = s.as_ref();
    // Beyond the ellipsoid's long axis: its tip at x = 14.
    let h = r
        .closest_point(Vec3::new(20.0, 0.0, 0.0), f32::INFINITY, !0)
        .unwrap();
    assert_eq!((h.inst, h.geom, h.prim), (0, ball, 0));
    assert!((h.point - Vec3::new(14.0, 0.0, 0.0)).length() < 1e-5 && (h.dist - 6.0).abs() < 1e-5);
    // Above the scaled triangle's interior: it spans (0..2, 0..2) at z = -5.
    let h = r
        .closest_point(Vec3::new(0.5, 0.5, -2.0), f32::INFINITY, !0)
        .unwrap();
    assert_eq!(
        (h.inst, h.geom, h.point, h.dist),
        (1, tri, Vec3::new(0.5, 0.5, -5.0), 3.0)
    );
    assert_eq!((h.u, h.v), (0.25, 0.25));
    // A mask that admits neither instance finds nothing; a radius too small finds nothing.
    s.set_geometry_mask(ball, 2);
    s.set_geometry_mask(tri, 2);
    s.commit().unwrap();
    assert_eq!(s.as_ref().closest_point(Vec3::ZERO, f32::INFINITY, 1), None);
    assert_eq!(
        s.as_ref().closest_point(Vec3::new(0.5, 0.5, -2.0), 2.9, 2),
        None
    );
}
