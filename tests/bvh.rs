//! The BVH's answers equal brute force, bit for bit: the proof that the tree and its traversal
//! are right. For every tier and width, on proptest scenes (random soups, clusters, duplicated,
//! degenerate and zero-area triangles, axis-aligned quads, scales 1e-6…1e6, offsets to 1e6, and
//! extreme scenes of 1e-13…1e33) and rays (from inside and outside the scene's bounds,
//! axis-parallel with ±0 components, aimed at vertices and edges, with ranges, and invalid), the
//! single-ray, packet and batch traversals give the same hit/miss, `t`, `u`, `v` bits and
//! primitive index as `query::closest` over the slice, and the same occlusion as
//! `query::occluded`.
#![cfg(all(feature = "triangle", feature = "sphere", feature = "alloc"))]
use octoray_testkit as testkit;

use octoray::bvh::traverse::{
    closest, closest_packet, closest_ray, closest_t_packet, occluded, occluded_packet, occluded_ray,
};
use octoray::bvh::{Bvh8, Bvh8Node, Bvh8Ref, BvhError, BLOCK, EMPTY, PAD};
use octoray::glam::Vec3;
use octoray::kernels::{
    Exact, ExactCulled, Kernel, MollerTrumbore, MollerTrumboreCulled, NaiveSphere, StableSphere,
    Watertight, WatertightCulled,
};
use octoray::packet::{f32x16, f32x4, f32x8};
use octoray::prim::Primitive;
use octoray::query;
use octoray::{Hit, PackedSphere, PackedTriangle, Ray, VertexTriangle};
use octoray::{LaneMask, Lanes, RayLanes, Scalar};
use proptest::prelude::*;
use testkit::mesh::crack_suite_with;
use testkit::strategies::{pack_triangles, pack_vertex_triangles};
use testkit::Rng;
use wide::f64x4;

fn bits(h: Option<Hit>) -> Option<(u32, u32, u32, u32)> {
    h.map(|h| (h.t.to_bits(), h.u.to_bits(), h.v.to_bits(), h.prim))
}

/// Checks every traversal against brute force on `rays`; returns the number of hits.
fn check<L: Lanes, K: Kernel<L>>(prims: &[K::Prim], rays: &[Ray]) -> usize {
    let tree = Bvh8::build(prims);
    // Every built tree passes the validation of untrusted slices, and traverses the same from it.
    let bvh = Bvh8Ref::<K::Prim>::new(tree.nodes(), tree.blocks(), tree.ids(), prims.len())
        .expect("a built tree validates");
    assert_eq!(bvh.prims(), prims.len());
    let mut batch = vec![None; rays.len()];
    closest::<L, K>(bvh, rays, &mut batch);
    let mut occ = vec![false; rays.len()];
    occluded::<L, K>(bvh, rays, &mut occ);
    let mut hits = 0;
    for (c, chunk) in rays.chunks(L::LANES).enumerate() {
        let p = RayLanes::<L>::load(chunk);
        let brute = query::closest::<L, K>(&p, prims);
        let packet = closest_packet::<L, K>(bvh, &p);
        let (tm, tt) = closest_t_packet::<L, K>(bvh, &p);
        let any_brute = query::occluded::<L, K>(&p, prims).bitmask();
        let any_packet = occluded_packet::<L, K>(bvh, &p).bitmask();
        for (i, ray) in chunk.iter().enumerate() {
            let want = bits(brute.lane(i));
            let k = c * L::LANES + i;
            assert_eq!(
                bits(packet.lane(i)),
                want,
                "packet {} {}, ray {ray:?}",
                std::any::type_name::<K>(),
                std::any::type_name::<L>()
            );
            assert_eq!(
                bits(closest_ray::<L, K>(bvh, ray)),
                want,
                "single, ray {ray:?}"
            );
            assert_eq!(bits(batch[k]), want, "batch, ray {ray:?}");
            assert_eq!((tm.bitmask() >> i) & 1 == 1, want.is_some());
            if let Some(w) = want {
                assert_eq!(Lanes::lane(tt, i).to_f32().to_bits(), w.0);
                hits += 1;
            }
            let a = (any_brute >> i) & 1 == 1;
            assert_eq!(a, want.is_some(), "any-hit agrees with closest-hit");
            assert_eq!((any_packet >> i) & 1 == 1, a, "any packet, ray {ray:?}");
            assert_eq!(occluded_ray::<L, K>(bvh, ray), a, "any single, ray {ray:?}");
            assert_eq!(occ[k], a, "occluded batch, ray {ray:?}");
        }
    }
    hits
}

/// A scene of `n` triangles of one of several kinds, at a random scale and offset.
/// Scale and offset exponents (base 10) of the scenes.
#[derive(Clone, Copy)]
struct Range {
    scale: (f32, f32),
    offset: f32,
    /// Rays also get hostile ranges: negative, infinite, NaN and empty `[t_min, t_max]`.
    hostile_ranges: bool,
}

/// The ordinary range: scales 1e-6…1e6, offsets to 1e6.
const ORDINARY: Range = Range {
    scale: (-6.0, 6.0),
    offset: 6.0,
    hostile_ranges: false,
};

/// Extreme triangle scenes: scales 1e-13…1e33, offsets to 1e34. Outside the standard tier's
/// range (its products under- and overflow: a miss) and, at the top, the f32 watertight tier's
/// (overflow: a miss); the answers must still be equal. Half the rays get hostile ranges.
const EXTREME: Range = Range {
    scale: (-13.0, 33.0),
    offset: 34.0,
    hostile_ranges: true,
};

/// Sphere scenes: scales 1e-5…1e5, offsets to 1e5.
const ORDINARY_SPHERES: Range = Range {
    scale: (-5.0, 5.0),
    offset: 5.0,
    hostile_ranges: false,
};

/// Extreme sphere scenes: scales 1e-15…1e15 (radii from 1e-18: r² stays a normal f32), where
/// unnormalised directions overflow the discriminant (a miss).
const EXTREME_SPHERES: Range = Range {
    scale: (-15.0, 15.0),
    offset: 15.0,
    hostile_ranges: true,
};

fn triangles(rng: &mut Rng, range: Range) -> (Vec<[Vec3; 3]>, Vec3, f32) {
    let kind = rng.next_u64() % 5;
    let n = 1 + (rng.next_u64() % 300) as usize;
    let s = 10f32.powf(rng.range(range.scale.0, range.scale.1));
    let off = if rng.below(2) == 0 {
        Vec3::ZERO
    } else {
        rng.vec3(1.0) * 10f32.powf(rng.range(0.0, range.offset))
    };
    let mut tris = Vec::with_capacity(n);
    let centers: Vec<Vec3> = (0..3).map(|_| rng.vec3(s)).collect();
    for i in 0..n {
        let t = match kind {
            // Soup.
            0 => {
                let a = off + rng.vec3(s);
                [a, a + rng.vec3(s * 0.3), a + rng.vec3(s * 0.3)]
            }
            // Clusters of small triangles.
            1 => {
                let c = off + centers[i % 3] + rng.vec3(s * 0.01);
                [c, c + rng.vec3(s * 0.02), c + rng.vec3(s * 0.02)]
            }
            // Duplicates (exact copies) and shared vertices.
            2 if i > 0 && rng.below(2) == 0 => tris[(rng.next_u64() % i as u64) as usize],
            // Degenerate: zero area, collinear, repeated vertex.
            3 if rng.below(3) == 0 => {
                let a = off + rng.vec3(s);
                let b = a + rng.vec3(s * 0.3);
                match rng.next_u64() % 3 {
                    0 => [a, a, b],
                    1 => [a, b, a + (b - a) * 0.5],
                    _ => [a, a, a],
                }
            }
            // Axis-aligned quads (two triangles each), in a grid.
            4 => {
                let cell = s * 0.1;
                let g = Vec3::new((i % 7) as f32, ((i / 7) % 7) as f32, (i / 49) as f32) * cell;
                let a = off + g;
                let axis = i % 3;
                let (u, v) = match axis {
                    0 => (Vec3::Y * cell, Vec3::Z * cell),
                    1 => (Vec3::Z * cell, Vec3::X * cell),
                    _ => (Vec3::X * cell, Vec3::Y * cell),
                };
                if i % 2 == 0 {
                    [a, a + u, a + u + v]
                } else {
                    [a, a + u + v, a + v]
                }
            }
            _ => {
                let a = off + rng.vec3(s);
                [a, a + rng.vec3(s * 0.3), a + rng.vec3(s * 0.3)]
            }
        };
        tris.push(t);
    }
    (tris, off, s)
}

/// Rays for a scene at `off` of size `s` aimed at `targets`: coherent groups (one origin) and
/// incoherent ones, from inside and outside the bounds, axis-parallel, aimed at vertices and
/// edge points, with random ranges (with `hostile`, half of them negative, infinite, NaN or
/// empty), and a few invalid.
fn rays(rng: &mut Rng, targets: &[Vec3], off: Vec3, s: f32, n: usize, hostile: bool) -> Vec<Ray> {
    let mut out = Vec::with_capacity(n);
    let mut origin = off + rng.vec3(2.0 * s);
    for i in 0..n {
        if i % 16 == 0 || rng.below(4) == 0 {
            origin = if rng.below(2) == 0 {
                off + rng.vec3(0.5 * s)
            } else {
                off + rng.vec3(3.0 * s)
            };
        }
        let target = targets[(rng.next_u64() % targets.len() as u64) as usize];
        let mut dir = match rng.next_u64() % 6 {
            0 => rng.vec3(1.0),
            1 => {
                // Axis-parallel, with signed zeros.
                let mut d = [0.0f32, -0.0, 0.0];
                d[(rng.next_u64() % 3) as usize] = if rng.below(2) == 0 { 1.0 } else { -1.0 };
                Vec3::from(d)
            }
            _ => target - origin,
        };
        if rng.below(50) == 0 {
            dir = Vec3::new(f32::NAN, 1.0, 0.0);
        }
        let (t_min, t_max) = if hostile && rng.below(2) == 0 {
            match rng.next_u64() % 9 {
                0 => (rng.range(-2.0, 0.5), rng.range(-0.5, 2.0)),
                1 => (f32::NEG_INFINITY, rng.range(-1.0, 2.0)),
                2 => (rng.range(-3.0, 3.0), f32::NAN),
                3 => (f32::NAN, rng.range(-1.0, 2.0)),
                4 => (rng.range(0.0, 1.0), rng.range(0.0, 1.0)),
                5 => (-0.0, 0.0),
                6 => (f32::NEG_INFINITY, f32::INFINITY),
                7 => (f32::INFINITY, f32::INFINITY),
                _ => (-1e30, 1e30),
            }
        } else {
            match rng.next_u64() % 5 {
                0 => (rng.range(0.0, 0.5), rng.range(0.5, 2.0)),
                1 => (0.0, 1.0),
                _ => (0.0, f32::INFINITY),
            }
        };
        out.push(Ray::with_range(origin, dir, t_min, t_max));
    }
    out
}

/// Coherent groups of 16 rays (every width's packets inside one group): one origin region and
/// one direction octant per group, aimed near one target, as camera packets are, so packet
/// traversal takes its frustum path. Some groups are axis-parallel (the same signed zero in
/// every lane), some lanes have their own ranges, a NaN `t_min` or a NaN direction.
fn coherent_rays(rng: &mut Rng, targets: &[Vec3], off: Vec3, s: f32, groups: usize) -> Vec<Ray> {
    let mut out = Vec::with_capacity(16 * groups);
    for _ in 0..groups {
        let o = if rng.below(2) == 0 {
            off + rng.vec3(0.5 * s)
        } else {
            off + rng.vec3(3.0 * s)
        };
        let target = targets[(rng.next_u64() % targets.len() as u64) as usize];
        let mut base = target - o;
        let flat = rng.below(4) == 0;
        if flat {
            // One component zero in every lane, with one sign for the group.
            let k = (rng.next_u64() % 3) as usize;
            let mut d = base.to_array();
            d[k] = if rng.below(2) == 0 { 0.0 } else { -0.0 };
            base = Vec3::from(d);
        }
        let spread = [0.0, 1e-3, 0.05][(rng.next_u64() % 3) as usize];
        for _ in 0..16 {
            let origin = o + rng.vec3(spread * s);
            let jitter = rng.vec3(spread * base.length());
            // The group's signs on every axis (zero components stay the group's zero).
            let dir = Vec3::from(core::array::from_fn::<f32, 3, _>(|k| {
                let b = base[k];
                if b == 0.0 {
                    b
                } else {
                    (b + jitter[k]).abs().copysign(b)
                }
            }));
            let (mut t_min, t_max) = match rng.next_u64() % 6 {
                0 => (rng.range(0.0, 0.5), rng.range(0.5, 2.0)),
                1 => (0.0, 1.0),
                _ => (0.0, f32::INFINITY),
            };
            if rng.below(40) == 0 {
                t_min = f32::NAN;
            }
            let dir = if rng.below(40) == 0 {
                Vec3::new(f32::NAN, 1.0, 0.0)
            } else {
                dir
            };
            out.push(Ray::with_range(origin, dir, t_min, t_max));
        }
    }
    out
}

fn targets(tris: &[[Vec3; 3]], rng: &mut Rng) -> Vec<Vec3> {
    tris.iter()
        .map(|t| match rng.next_u64() % 4 {
            0 => t[0],
            1 => t[0] + (t[1] - t[0]) * 0.5,
            2 => (t[0] + t[1] + t[2]) / 3.0,
            _ => t[2],
        })
        .collect()
}

fn triangle_scene(seed: u64, range: Range) {
    let mut rng = Rng(seed);
    let (tris, off, s) = triangles(&mut rng, range);
    let tg = targets(&tris, &mut rng);
    let mut rays = rays(&mut rng, &tg, off, s, 96, range.hostile_ranges);
    rays.extend(coherent_rays(&mut rng, &tg, off, s, 4));
    let (packed, verts) = (pack_triangles(&tris), pack_vertex_triangles(&tris));
    check::<f32x8, MollerTrumbore>(&packed, &rays);
    check::<f32x16, MollerTrumbore>(&packed, &rays);
    check::<f32x4, MollerTrumboreCulled>(&packed, &rays);
    check::<f32x8, Watertight>(&verts, &rays);
    check::<f32x16, WatertightCulled>(&verts, &rays);
    check::<f32x8, Exact>(&verts, &rays);
    check::<f32x16, ExactCulled>(&verts, &rays);
    check::<f64x4, MollerTrumbore>(&packed, &rays);
    check::<f64x4, Watertight>(&verts, &rays);
}

fn sphere_scene(seed: u64, range: Range) {
    let mut rng = Rng(seed);
    let n = 1 + (rng.next_u64() % 200) as usize;
    let s = 10f32.powf(rng.range(range.scale.0, range.scale.1));
    let off = rng.vec3(1.0) * 10f32.powf(rng.range(0.0, range.offset));
    let spheres: Vec<(Vec3, f32)> = (0..n)
        .map(|i| {
            let r = match i % 7 {
                0 => 0.0,
                1 => -1.0,
                _ => s * rng.range(0.001, 0.1),
            };
            (off + rng.vec3(s), r)
        })
        .collect();
    let tg: Vec<Vec3> = spheres.iter().map(|c| c.0).collect();
    let mut rays = rays(&mut rng, &tg, off, s, 96, range.hostile_ranges);
    rays.extend(coherent_rays(&mut rng, &tg, off, s, 4));
    let packed: Vec<PackedSphere> = spheres
        .iter()
        .map(|&(c, r)| PackedSphere::new(c, r))
        .collect();
    check::<f32x8, StableSphere>(&packed, &rays);
    check::<f32x16, StableSphere>(&packed, &rays);
    check::<f32x8, NaiveSphere>(&packed, &rays);
    check::<f64x4, StableSphere>(&packed, &rays);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn bvh_equals_brute_force_on_triangle_scenes(seed in any::<u64>()) {
        triangle_scene(seed, ORDINARY);
    }

    #[test]
    fn bvh_equals_brute_force_on_sphere_scenes(seed in any::<u64>()) {
        sphere_scene(seed, ORDINARY_SPHERES);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    // Found three kernel bugs (tests/hostile.rs): a sphere hit at t = 0 from an overflowed
    // discriminant, a standard-tier hit from subnormal products, and a watertight t_max decided
    // on a different t than the one reported.
    #[test]
    fn bvh_equals_brute_force_on_extreme_triangle_scenes(seed in any::<u64>()) {
        triangle_scene(seed, EXTREME);
    }

    #[test]
    fn bvh_equals_brute_force_on_extreme_sphere_scenes(seed in any::<u64>()) {
        sphere_scene(seed, EXTREME_SPHERES);
    }
}

#[test]
fn many_hits_are_checked() {
    // The equality is not vacuous: a fixed scene and its rays do hit.
    let mut rng = Rng(7);
    let (tris, off, s) = triangles(&mut rng, ORDINARY);
    let tg = targets(&tris, &mut rng);
    let rays = rays(&mut rng, &tg, off, s, 512, false);
    let hits = check::<f32x8, MollerTrumbore>(&pack_triangles(&tris), &rays);
    assert!(hits > 100, "only {hits} hits of 512 rays");
}

#[test]
fn ties_go_to_the_lower_index_like_brute_force() {
    // 40 copies of one triangle, shuffled among others: every ray through it hits all copies at
    // the same t; the BVH must report the lowest index, as brute force does.
    let v = Vec3::new;
    let mut tris = vec![];
    for i in 0..200 {
        let x = (i % 20) as f32;
        tris.push(VertexTriangle::new(
            v(x, 0.0, 5.0),
            v(x + 1.0, 0.0, 5.0),
            v(x, 1.0, 5.0),
        ));
    }
    for k in [3usize, 17, 44, 90, 151, 199] {
        tris[k] = tris[2];
    }
    let rays: Vec<Ray> = (0..64)
        .map(|i| Ray::new(v(2.2 + 0.001 * i as f32, 0.2, 0.0), v(0.0, 0.0, 1.0)))
        .collect();
    check::<f32x8, Watertight>(&tris, &rays);
    let bvh = Bvh8::build(&tris);
    assert_eq!(
        closest_ray::<f32x8, Watertight>(bvh.as_ref(), &rays[0])
            .unwrap()
            .prim,
        2
    );
}

#[test]
fn crack_suite_through_the_bvh_has_no_escapes() {
    // The closed meshes of tests/watertight.rs, traced through the BVH (packets with hybrid
    // fallback): the watertight tier still lets no ray escape, and the standard tier's cracks
    // are the same ones as brute force's.
    let rows = crack_suite_with(2_500, |tris, rays| {
        let bvh = Bvh8::build(tris);
        let mut out = vec![false; rays.len()];
        occluded::<f32x8, Watertight>(bvh.as_ref(), rays, &mut out);
        out.iter().filter(|&&o| !o).count()
    });
    let mut total = 0;
    for (mesh, rays, escapes) in rows {
        println!("{mesh}: {rays} rays, {escapes} escapes through the BVH");
        assert_eq!(
            escapes, 0,
            "{mesh}: the watertight tier leaked through the BVH"
        );
        total += rays;
    }
    assert_eq!(total, 20_000);
}

#[test]
fn empty_and_unhittable_scenes_miss() {
    let ray = Ray::new(Vec3::ZERO, Vec3::Z);
    let none: Vec<PackedTriangle> = vec![];
    let b = Bvh8::build(&none);
    assert_eq!(b.stats().prims, 0);
    assert_eq!(closest_ray::<f32x8, MollerTrumbore>(b.as_ref(), &ray), None);
    let p = RayLanes::<f32x8>::load(&[ray; 8]);
    assert_eq!(
        closest_packet::<f32x8, MollerTrumbore>(b.as_ref(), &p)
            .mask
            .bitmask(),
        0
    );
    // Non-finite triangles are left out and never hit.
    let bad = vec![
        PackedTriangle::new(Vec3::new(f32::NAN, 0.0, 1.0), Vec3::X, Vec3::Y),
        PackedTriangle::new(Vec3::new(f32::INFINITY, 0.0, 1.0), Vec3::X, Vec3::Y),
    ];
    let b = Bvh8::build(&bad);
    assert_eq!((b.stats().prims, b.stats().skipped), (0, 2));
    assert_eq!(closest_ray::<f32x8, MollerTrumbore>(b.as_ref(), &ray), None);
}

/// The threaded build (`try_build_with` and rayon's join, the facade's `rayon` feature) gives
/// the same tree, bit for bit, as the single-threaded one: on scenes large enough to split
/// across threads many times (a 320 000-triangle icosphere, a 60 000-triangle soup with
/// duplicates and zero-area triangles, all centres equal), on a pool of 1, 2 and 4 threads.
#[test]
fn threaded_build_equals_single_threaded_build() {
    use octoray::parallel::Rayon;
    let (v, f) = testkit::icosphere::icosphere(7);
    let sphere: Vec<VertexTriangle> = f
        .iter()
        .map(|t| VertexTriangle::new(v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]))
        .collect();
    let mut rng = Rng(5);
    let soup: Vec<VertexTriangle> = (0..60_000)
        .map(|i| {
            let a = rng.vec3(100.0);
            match i % 5 {
                0 => VertexTriangle::new(a, a, a + Vec3::X),
                1 => VertexTriangle::new(Vec3::ZERO, Vec3::X, Vec3::Y),
                _ => VertexTriangle::new(a, a + rng.vec3(1.0), a + rng.vec3(1.0)),
            }
        })
        .collect();
    let same: Vec<VertexTriangle> = (0..20_000)
        .map(|_| VertexTriangle::new(Vec3::ZERO, Vec3::X, Vec3::Y))
        .collect();
    for tris in [&sphere, &soup, &same] {
        let one = Bvh8::build(tris);
        for threads in [1, 2, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            let par = pool.install(|| Bvh8::try_build_with(tris, &Rayon).expect("build"));
            assert_eq!(
                bytemuck::cast_slice::<Bvh8Node, u8>(one.nodes()),
                bytemuck::cast_slice::<Bvh8Node, u8>(par.nodes()),
                "{} triangles, {threads} threads",
                tris.len()
            );
            assert_eq!(one.ids(), par.ids());
            assert_eq!(
                bytemuck::cast_slice::<_, u8>(one.blocks()),
                bytemuck::cast_slice::<_, u8>(par.blocks())
            );
            assert_eq!(one.stats(), par.stats());
        }
    }
}

#[test]
fn build_is_deterministic_and_plain_data() {
    let mut rng = Rng(99);
    let (tris, ..) = triangles(&mut rng, ORDINARY);
    let verts: Vec<VertexTriangle> = tris
        .iter()
        .map(|t| VertexTriangle::new(t[0], t[1], t[2]))
        .collect();
    let a = Bvh8::build(&verts);
    let b = Bvh8::build(&verts);
    let bytes: &[u8] = bytemuck::cast_slice(a.nodes());
    assert_eq!(bytes, bytemuck::cast_slice::<Bvh8Node, u8>(b.nodes()));
    assert_eq!(a.ids(), b.ids());
    let block_bytes: &[u8] = bytemuck::cast_slice(a.blocks());
    assert_eq!(block_bytes, bytemuck::cast_slice::<_, u8>(b.blocks()));
    // Written out as bytes and read back as borrowed slices, it traverses the same.
    let nodes: Vec<Bvh8Node> = bytemuck::pod_collect_to_vec(bytes);
    let blocks: Vec<[f32; BLOCK]> = bytemuck::pod_collect_to_vec(block_bytes);
    let r =
        Bvh8Ref::<VertexTriangle>::new(&nodes, &blocks, a.ids(), verts.len()).expect("valid tree");
    let ray = Ray::new(Vec3::new(0.0, 0.0, -1e7), Vec3::Z);
    assert_eq!(
        bits(closest_ray::<f32x8, Watertight>(r, &ray)),
        bits(query::closest::<f32, Watertight>(&RayLanes::single(&ray), &verts).lane(0))
    );
}

#[test]
fn bad_trees_are_rejected_not_traversed() {
    let tris = [VertexTriangle::new(Vec3::ZERO, Vec3::X, Vec3::Y)];
    let mut blocks = [[0.0f32; BLOCK]; 9];
    VertexTriangle::write_block(&tris, &mut blocks);
    let mut ids = [PAD; BLOCK];
    ids[0] = 0;
    type R<'a> = Bvh8Ref<'a, VertexTriangle>;
    let mut n = Bvh8Node::EMPTY;
    n.child[0] = 0; // an inner node pointing at itself: a cycle
    assert_eq!(
        R::new(&[n], &blocks, &ids, 1).unwrap_err(),
        BvhError::BadNodeRef { node: 0 }
    );
    n.child[0] = 0;
    n.count[0] = BLOCK as u32 + 1; // a leaf past the blocks
    assert_eq!(
        R::new(&[n], &blocks, &ids, 1).unwrap_err(),
        BvhError::BadLeaf { node: 0 }
    );
    n.child[0] = 1; // a leaf not starting a block
    n.count[0] = 1;
    assert_eq!(
        R::new(&[n], &blocks, &ids, 1).unwrap_err(),
        BvhError::BadLeaf { node: 0 }
    );
    n.child[0] = 0;
    for a in 0..3 {
        (n.lo[a][0], n.hi[a][0]) = (-1.0, 2.0);
    }
    let one = [n];
    let r = R::new(&one, &blocks, &ids, 1).expect("a one-leaf tree");
    let ray = Ray::new(Vec3::new(0.25, 0.25, -1.0), Vec3::Z);
    assert_eq!(
        closest_ray::<f32x8, Watertight>(r, &ray).map(|h| h.prim),
        Some(0)
    );
    assert_eq!(
        R::new(&[n], &blocks, &[], 1).unwrap_err(),
        BvhError::LengthMismatch { blocks: 9, ids: 0 }
    );
    assert_eq!(
        R::new(&[n], &blocks[..8], &ids, 1).unwrap_err(),
        BvhError::LengthMismatch {
            blocks: 8,
            ids: BLOCK
        }
    );
    assert_eq!(
        R::new(&[n], &blocks, &ids[..1], 1).unwrap_err(),
        BvhError::LengthMismatch { blocks: 9, ids: 1 }
    );
    // A chain deeper than MAX_DEPTH.
    let deep: Vec<Bvh8Node> = (0..70u32)
        .map(|i| {
            let mut n = Bvh8Node::EMPTY;
            n.child[0] = if i == 69 { EMPTY } else { i + 1 };
            n
        })
        .collect();
    assert_eq!(
        R::new(&deep, &blocks, &ids, 1).unwrap_err(),
        BvhError::TooDeep
    );
}

#[test]
#[should_panic(expected = "out has 3 entries for 4 rays")]
fn batch_length_mismatch_panics() {
    let tris = [PackedTriangle::new(Vec3::ZERO, Vec3::X, Vec3::Y)];
    let b = Bvh8::build(&tris);
    let mut out = [None; 3];
    closest::<f32x8, MollerTrumbore>(b.as_ref(), &[Ray::new(Vec3::ZERO, Vec3::Z); 4], &mut out);
}

#[test]
fn regression_zero_area_triangle_scene() {
    // Found by the equality proptest against the (since removed) fast tier, which reported a hit
    // (u = v = 0) on a collinear triangle far from the ray; kept for the remaining tiers.
    triangle_scene(10981392969920591453, ORDINARY);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4096))]
    /// The packet frustum never drops a child some valid lane's slab test keeps: random nodes
    /// (boxes at any scale, empty slots, flat boxes) against coherent packets (shared signs,
    /// zero components, NaN ranges and directions in some lanes), every t_max.
    #[test]
    #[allow(clippy::needless_range_loop)] // children are columns of the node's rows
    fn frustum_keeps_every_child_a_lane_enters(seed in any::<u64>()) {
        use octoray::bvh::slab::{slab, BoxRay, Frustum};
        use octoray::V3;
        let mut rng = Rng(seed);
        let s = 10f32.powf(rng.range(-6.0, 6.0));
        let off = rng.vec3(1.0) * 10f32.powf(rng.range(-3.0, 6.0));
        let target = off + rng.vec3(s);
        let rays = coherent_rays(&mut rng, &[target], off, s, 1);
        let rays = &rays[..8];
        let packet = RayLanes::<f32x8>::load(rays);
        let br = BoxRay::new(&packet);
        let Some(f) = Frustum::new(&br) else {
            // Only when no lane is valid (the group shares its signs).
            prop_assert!(br.valid.none());
            return Ok(());
        };
        let valid: Vec<usize> = (0..8).filter(|i| (br.valid.bitmask() >> i) & 1 == 1).collect();
        // Boxes at the decision boundary of some lane: around, or with a face through, a point
        // of that lane's ray, nudged by 0 to 2^-14 of its magnitude, some of them points or
        // flat; and empty slots.
        let mut node = [[0.0f32; 8]; 8];
        let mut t_at = [0.0f32; 8];
        for c in 0..8 {
            if rng.below(10) == 0 {
                for k in 0..3 {
                    node[k][c] = f32::INFINITY;
                    node[3 + k][c] = f32::NEG_INFINITY;
                }
                continue;
            }
            let r = rays[valid[(rng.next_u64() % valid.len() as u64) as usize]];
            let t = rng.range(0.0, 2.0) * s / r.dir.length().max(1e-30);
            t_at[c] = t;
            let p = r.at(t);
            let m = p.abs().max_element().max(f32::MIN_POSITIVE);
            let nudge = [0.0, 1.0 / 1_048_576.0, 1.0 / 131_072.0, 1.0 / 16_384.0]
                [(rng.next_u64() % 4) as usize];
            let p = p + rng.vec3(m * nudge);
            let e = match rng.next_u64() % 4 {
                0 => Vec3::ZERO,
                1 => rng.vec3(m * 1e-6).abs(),
                _ => rng.vec3(s * 0.01).abs(),
            };
            let face = rng.below(2) == 0;
            for k in 0..3 {
                let (lo, hi) = if face { (p[k], p[k] + e[k]) } else { (p[k] - e[k], p[k] + e[k]) };
                node[k][c] = lo;
                node[3 + k][c] = hi;
            }
            if rng.below(2) == 0 {
                // Beside the ray on one axis, at the edge of what the slab test keeps: the
                // origin's slack plus a few multiples of the widening.
                let k = (rng.next_u64() % 3) as usize;
                let slack = r.origin.abs().max_element() / 131_072.0;
                let gap = slack + m * 3.6e-7 * rng.range(0.0, 4.0);
                if rng.below(2) == 0 {
                    node[k][c] = p[k] + gap;
                    node[3 + k][c] = p[k] + gap + e[k];
                } else {
                    node[k][c] = p[k] - gap - e[k];
                    node[3 + k][c] = p[k] - gap;
                }
            }
        }
        for round in 0..4 {
            // Per-lane bounds (a closest-hit packet's `cull`): infinite, at a child's point,
            // just before or after it, or NaN; the frustum gets the largest (NaN if any is).
            let cull: [f32; 8] = core::array::from_fn(|_| {
                let t = t_at[(rng.next_u64() % 8) as usize];
                match (rng.next_u64() + round) % 6 {
                    0 => f32::INFINITY,
                    1 => t,
                    2 => t * (1.0 - 1.0 / 1_048_576.0),
                    3 => t * (1.0 + 1.0 / 1_048_576.0),
                    4 if rng.below(8) == 0 => f32::NAN,
                    _ => t * 0.5,
                }
            });
            let t_max = valid.iter().fold(f32::NEG_INFINITY, |m, &i| {
                if m.is_nan() || cull[i].is_nan() { f32::NAN } else { m.max(cull[i]) }
            });
            let passed = f.children(&node, t_max);
            for c in 0..8 {
                let lo = V3::<f32x8>::splat([node[0][c], node[1][c], node[2][c]]);
                let hi = V3::<f32x8>::splat([node[3][c], node[4][c], node[5][c]]);
                let lanes = slab(lo, hi, &br, f32x8::from(cull)).0.bitmask();
                prop_assert!(
                    lanes == 0 || (passed >> c) & 1 == 1,
                    "child {c} dropped, lanes {lanes:#b} enter, t_max {t_max}"
                );
            }
        }
    }
}

/// One case of [`slab_test_keeps_every_box_the_ray_meets`]: a ray and a box at its decision edge,
/// or `None` when the draw is unusable. The ray's point `p` is computed in f64 and rounded once,
/// so the exact crossing distances lie between f32 values (from a representable `t` they would
/// all round back to it).
fn slab_case(rng: &mut Rng) -> Option<(Ray, Vec3, Vec3)> {
    // Box scale, distance to the box, direction length; a quarter of the cases with huge
    // directions and distances in the subnormal range of t (where only the absolute widening
    // helps).
    let (s, dist, len) = if rng.below(4) == 0 {
        let len = 10f32.powf(rng.range(30.0, 37.0));
        let dist = len * 10f32.powf(rng.range(-40.0, -38.8));
        (dist * 10f32.powf(rng.range(-3.0, 0.0)), dist, len)
    } else {
        let s = 10f32.powf(rng.range(-6.0, 6.0));
        let dist = s * 10f32.powf(rng.range(0.0, 4.0));
        (s, dist, 10f32.powf(rng.range(-3.0, 3.0)))
    };
    // The origin at 0 (no origin slack), or small or large against the distance.
    let origin = match rng.below(3) {
        0 => Vec3::ZERO,
        1 => rng.vec3(dist * 1e-4),
        _ => {
            let m = dist * 10f32.powf(rng.range(-3.0, 1.0));
            rng.vec3(m)
        }
    };
    let unit = rng.vec3(1.0);
    if unit.length() < 1e-6 {
        return None;
    }
    let dir = unit * len;
    let t = f64::from(dist) / f64::from(unit.length()) / f64::from(len)
        * (1.0 + f64::from(rng.range(0.0, 1.0)));
    let p = (origin.as_dvec3() + dir.as_dvec3() * t).as_vec3();
    // Per axis: p on the lower face, the upper face, or inside.
    let (mut lo, mut hi) = (p, p);
    for k in 0..3 {
        let e = s * rng.range(0.0, 1.0);
        match rng.below(3) {
            0 => hi[k] = p[k] + e,
            1 => lo[k] = p[k] - e,
            _ => (lo[k], hi[k]) = (p[k] - e, p[k] + e),
        }
    }
    if rng.below(2) == 0 {
        // Through an edge: the ray enters axis a's slab and leaves axis b's at p (near and far
        // equal but for roundings).
        let a = rng.below(3) as usize;
        let b = (a + 1 + rng.below(2) as usize) % 3;
        let e = s * rng.range(0.0, 1.0);
        (lo[a], hi[a]) = if dir[a] >= 0.0 {
            (p[a], p[a] + e)
        } else {
            (p[a] - e, p[a])
        };
        (lo[b], hi[b]) = if dir[b] >= 0.0 {
            (p[b] - e, p[b])
        } else {
            (p[b], p[b] + e)
        };
    }
    // One face of one axis moved by 0 to 3 ulps either way.
    let k = rng.below(3) as usize;
    for _ in 0..rng.below(4) {
        match rng.below(4) {
            0 => lo[k] = lo[k].next_up(),
            1 => lo[k] = lo[k].next_down(),
            2 => hi[k] = hi[k].next_up(),
            _ => hi[k] = hi[k].next_down(),
        }
    }
    if lo[k] > hi[k] {
        return None;
    }
    // Ranges ending at the box, just before it, or not at all.
    let t = t as f32;
    let t_max = match rng.below(4) {
        0 => f32::INFINITY,
        1 => t,
        2 => t.next_down(),
        _ => t * 2.0,
    };
    Some((Ray::with_range(origin, dir, 0.0, t_max), lo, hi))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(8192))]
    /// The slab test keeps every box the ray meets, decided exactly (`oracle::box_meets`), on
    /// boxes at a ray's decision edge ([`slab_case`], 16 per seed): a corner, an edge or a face
    /// through a point of the ray, then moved by up to 3 ulps; every scale, huge directions. It
    /// fails without the relative widening, and without the absolute one.
    #[test]
    fn slab_test_keeps_every_box_the_ray_meets(seed in any::<u64>()) {
        use octoray::bvh::slab::{slab, BoxRay};
        use octoray::V3;
        let mut rng = Rng(seed);
        for _ in 0..16 {
            let Some((ray, lo, hi)) = slab_case(&mut rng) else {
                continue;
            };
            let truth = testkit::oracle::box_meets(&ray, lo, hi);
            let br = BoxRay::<f32>::new(&RayLanes::single(&ray));
            let (lo3, hi3) = (V3::<f32>::splat(lo.to_array()), V3::<f32>::splat(hi.to_array()));
            let (kept, _) = slab(lo3, hi3, &br, ray.t_max);
            prop_assert!(
                truth != Some(true) || kept,
                "box {lo} {hi} rejected; ray {} {}, t_max {}",
                ray.origin,
                ray.dir,
                ray.t_max
            );
        }
    }
}

#[test]
fn slab_test_keeps_rays_in_a_face_plane_and_handles_signed_zero_and_subnormal_directions() {
    use octoray::bvh::slab::{slab, BoxRay};
    use octoray::V3;
    let lo = V3::<f32>::splat([0.0, 0.0, 0.0]);
    let hi = V3::<f32>::splat([1.0, 1.0, 1.0]);
    let ray = |o: Vec3, d: Vec3| BoxRay::<f32>::new(&RayLanes::single(&Ray::new(o, d)));
    // Along +z at x exactly on the lower (and then upper) x face, d.x = +0 and −0: (b − o)·(1/d)
    // is 0·inf = NaN there, which must not reject the box.
    for dx in [0.0f32, -0.0] {
        for x in [0.0f32, 1.0] {
            let mut r = ray(Vec3::new(x, 0.5, -1.0), Vec3::new(dx, 0.0, 1.0));
            // The slack moves o off the plane; put it back exactly on the face.
            r.o_entry.x = x;
            r.o_exit.x = x;
            let (m, near) = slab(lo, hi, &r, f32::INFINITY);
            assert!(m, "face-plane ray at x = {x}, d.x = {dx:?} lost the box");
            assert!(near <= 1.0);
        }
    }
    // Parallel to a face and outside the slab, on either side, with +0 and −0: rejected.
    for x in [2.0f32, -1.0] {
        for dx in [0.0f32, -0.0] {
            let r = ray(Vec3::new(x, 0.5, -1.0), Vec3::new(dx, 0.0, 1.0));
            assert!(!slab(lo, hi, &r, f32::INFINITY).0, "x = {x}, d.x = {dx:?}");
        }
    }
    // An empty slot's inverted box (lo = +inf, hi = −inf) is never entered, in any octant.
    let (elo, ehi) = (
        V3::<f32>::splat([f32::INFINITY; 3]),
        V3::<f32>::splat([f32::NEG_INFINITY; 3]),
    );
    for d in [
        Vec3::new(1.0, 2.0, 3.0),
        Vec3::new(-1.0, 2.0, -3.0),
        Vec3::new(0.0, -0.0, 1.0),
    ] {
        assert!(
            !slab(elo, ehi, &ray(Vec3::splat(0.5), d), f32::INFINITY).0,
            "{d}"
        );
    }
    // Entered through the upper faces (every component negative): the same answers.
    let r = ray(Vec3::new(0.5, 0.5, 2.0), Vec3::new(-0.0, -0.0, -1.0));
    let (m, near) = slab(lo, hi, &r, f32::INFINITY);
    assert!(m && (near - 1.0).abs() < 1e-4, "near = {near}");
    assert!(!slab(lo, hi, &r, 0.5).0);
    // A subnormal direction component (1/d overflows): that axis does not bound the ray.
    let r = ray(Vec3::new(0.5, 0.5, -1.0), Vec3::new(1e-40, 0.0, 1.0));
    assert!(slab(lo, hi, &r, f32::INFINITY).0);
    // Starting inside the box, and the range cut off before the box.
    let r = ray(Vec3::new(0.5, 0.5, 0.5), Vec3::new(1.0, 2.0, 3.0));
    assert!(slab(lo, hi, &r, f32::INFINITY).0);
    let r = ray(Vec3::new(0.5, 0.5, -1.0), Vec3::new(0.0, 0.0, 1.0));
    assert!(!slab(lo, hi, &r, 0.5).0);
    // NaN and zero directions are never valid.
    assert!(!ray(Vec3::ZERO, Vec3::ZERO).valid);
    assert!(!ray(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::Z).valid);
}
