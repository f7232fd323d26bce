//! Scenes of geometries and instances equal brute force over the instanced primitives, bit for
//! bit: several triangle and sphere geometries, instances with random affine transforms
//! (rotations, non-uniform and mirrored scales, shears, nearly singular and raw ones), masks,
//! filters, refits and moved instances; single rays, packets of every width and slices; the
//! scene's slices validated back from bytes; corrupted scenes rejected or traced without a panic.
#![cfg(all(feature = "triangle", feature = "sphere", feature = "alloc"))]
use crate::dyn_filter;
use octoray_testkit as testkit;

use octoray::bvh::{BuildOptions, PAD};
use octoray::glam::{Affine3A, Quat, Vec3};
use octoray::hit::{Candidate, Hit};
use octoray::kernels::{Kernel, MollerTrumbore, StableSphere, Watertight};
use octoray::lanes::{LaneMask, Lanes};
use octoray::prim::{PackedSphere, PackedTriangle, Primitive, Ray, RayLanes, VertexTriangle};
use octoray::scene::{
    Geometry, Instance, Member, Scene, SceneError, SceneParts, SceneRef, SceneTree, Trace, Tracer,
    Transform,
};
use octoray::tree::hit_order;
use octoray::{f32x16, f32x8, query};
use proptest::prelude::*;
use testkit::stored::{word, words, FIRST_MEMBER, FIRST_UNBOUNDED, LEVELS, MASK, PATHS, SLACK};
use testkit::Rng;
use wide::f64x4;

/// One geometry of a test world.
#[derive(Clone)]
pub(crate) enum Geom<T> {
    Tris(Vec<T>),
    Spheres(Vec<PackedSphere>),
}

/// What a placement places.
#[derive(Clone)]
pub(crate) enum Target {
    /// A set of geometries (sorted, one kind).
    Geoms(Vec<u32>),
    /// A group (of the world's list).
    Group(usize),
}

/// A placement of a set of geometries or a group.
#[derive(Clone)]
pub(crate) struct Place {
    pub target: Target,
    pub transform: Transform,
    pub mask: u32,
}

/// A test world: geometries (with masks), groups (each holding earlier groups), the world's
/// instances, and the scene built from them; brute force drops the hits of instance path
/// `banned` (what a filter rejecting it leaves).
pub(crate) struct World<T> {
    pub geoms: Vec<(Geom<T>, u32)>,
    pub groups: Vec<Vec<Place>>,
    pub insts: Vec<Place>,
    banned: Option<u32>,
}

impl<T: Primitive + Sync> World<T> {
    pub(crate) fn scene(&self) -> Scene<T, PackedSphere> {
        self.scene_with(BuildOptions::BINNED)
    }

    /// The scene, its geometries' trees built as `options` say.
    fn scene_with(&self, options: BuildOptions) -> Scene<T, PackedSphere> {
        let mut s = Scene::new();
        s.set_build_options(options);
        for (g, mask) in &self.geoms {
            let id = match g {
                Geom::Tris(p) => s.add_triangles(p).unwrap(),
                Geom::Spheres(p) => s.add_spheres(p).unwrap(),
            };
            s.set_geometry_mask(id, *mask);
        }
        for (g, places) in self.groups.iter().enumerate() {
            assert_eq!(s.add_group(), g as u32);
            for i in places {
                match &i.target {
                    Target::Geoms(geoms) => s.add_to_group(g as u32, geoms, i.transform, i.mask),
                    Target::Group(c) => {
                        s.place_group(Some(g as u32), *c as u32, i.transform, i.mask)
                    }
                };
            }
        }
        for i in &self.insts {
            match &i.target {
                Target::Geoms(geoms) => s.add_instance(geoms, i.transform, i.mask),
                Target::Group(c) => s.place_group(None, *c as u32, i.transform, i.mask),
            };
        }
        s.commit().expect("commit");
        s
    }
}

fn bits(h: Option<Hit>) -> Option<[u32; 6]> {
    h.map(|h| Hit::words(Some(h)))
}

/// Brute force: every admitted instance's primitives with its transformed ray; the nearest `t`,
/// ties to the lower instance, then the lower primitive. Also whether anything was hit.
fn brute<S1: Lanes, KT, KS>(
    w: &World<<KT as Kernel<S1>>::Prim>,
    ray: &Ray,
    mask: u32,
) -> (Option<Hit>, bool)
where
    KT: Kernel<S1>,
    KS: Kernel<S1, Prim = PackedSphere>,
{
    let mut best: Option<(S1::Scalar, Hit)> = None;
    let mut any = false;
    let mut path = 0;
    let mut found = Brute {
        best: &mut best,
        any: &mut any,
        all: None,
    };
    brute_level::<S1, KT, KS>(w, &w.insts, ray, mask, &mut path, &mut found);
    (best.map(|b| b.1), any)
}

/// Brute force's every hit: each admitted instance's primitives one at a time, in hit order.
fn brute_all<S1: Lanes, KT, KS>(
    w: &World<<KT as Kernel<S1>>::Prim>,
    ray: &Ray,
    mask: u32,
) -> Vec<Hit>
where
    KT: Kernel<S1>,
    KS: Kernel<S1, Prim = PackedSphere>,
{
    let (mut best, mut any, mut all) = (None, false, Vec::new());
    let mut found = Brute {
        best: &mut best,
        any: &mut any,
        all: Some(&mut all),
    };
    brute_level::<S1, KT, KS>(w, &w.insts, ray, mask, &mut 0, &mut found);
    all.sort_by(hit_order);
    all
}

/// What brute force gathers: the best hit, whether any, and (when asked) every hit.
struct Brute<'b, S> {
    best: &'b mut Option<(S, Hit)>,
    any: &'b mut bool,
    all: Option<&'b mut Vec<Hit>>,
}

/// Every hit of `ray` on each primitive of `prims` alone, as geometry `geom` of instance `inst`.
fn each_hit<S1: Lanes, K: Kernel<S1>>(
    r: &RayLanes<S1>,
    prims: &[K::Prim],
    geom: u32,
    inst: u32,
) -> Vec<Hit> {
    (0..prims.len())
        .filter_map(|i| {
            query::closest::<S1, K>(r, &prims[i..=i])
                .lane(0)
                .map(|h| Hit {
                    prim: i as u32,
                    geom,
                    inst,
                    ..h
                })
        })
        .collect()
}

/// [`brute`] over one level's placements, the ray in its space, `mask` the AND of the query's
/// and the placements' above; `path` counts the instance paths depth first.
#[allow(clippy::too_many_arguments)]
fn brute_level<S1: Lanes, KT, KS>(
    w: &World<<KT as Kernel<S1>>::Prim>,
    places: &[Place],
    ray: &Ray,
    mask: u32,
    path: &mut u32,
    found: &mut Brute<'_, S1::Scalar>,
) where
    KT: Kernel<S1>,
    KS: Kernel<S1, Prim = PackedSphere>,
{
    for inst in places {
        let ray = inst.transform.apply(ray);
        let geoms = match &inst.target {
            Target::Group(g) => {
                let places = &w.groups[*g];
                brute_level::<S1, KT, KS>(w, places, &ray, mask & inst.mask, path, found);
                continue;
            }
            Target::Geoms(geoms) => geoms,
        };
        let r = RayLanes::<S1>::single(&ray);
        for &geom in geoms {
            let (g, gmask) = &w.geoms[geom as usize];
            if inst.mask & gmask & mask == 0 || w.banned == Some(*path) {
                continue;
            }
            let (h, occ) = match g {
                Geom::Tris(p) => (
                    query::closest::<S1, KT>(&r, p),
                    query::occluded::<S1, KT>(&r, p),
                ),
                Geom::Spheres(p) => (
                    query::closest::<S1, KS>(&r, p),
                    query::occluded::<S1, KS>(&r, p),
                ),
            };
            *found.any |= occ.bitmask() & 1 == 1;
            if let Some(mut hit) = h.lane(0) {
                hit.geom = geom;
                hit.inst = *path;
                let t = h.t.lane(0);
                if found.best.is_none_or(|(bt, _)| t < bt) {
                    *found.best = Some((t, hit));
                }
            }
            if let Some(all) = found.all.as_deref_mut() {
                all.extend(match g {
                    Geom::Tris(p) => each_hit::<S1, KT>(&r, p, geom, *path),
                    Geom::Spheres(p) => each_hit::<S1, KS>(&r, p, geom, *path),
                });
            }
        }
        *path += 1;
    }
}

/// Every scene query (single, packet, slice; closest and occlusion) at width `L` equals brute
/// force at its scalar `S1`, under the query masks `masks`; returns the hits.
fn check<L: Lanes, S1: Lanes, KT, KS>(
    w: &World<<KT as Kernel<L>>::Prim>,
    scene: SceneRef<'_, <KT as Kernel<L>>::Prim, PackedSphere>,
    rays: &[Ray],
    masks: &[u32],
) -> usize
where
    KT: Kernel<L> + Kernel<S1, Prim = <KT as Kernel<L>>::Prim>,
    KS: Kernel<L, Prim = PackedSphere> + Kernel<S1, Prim = PackedSphere>,
{
    let mut hits = 0;
    for &mask in masks {
        let mut batch = vec![None; rays.len()];
        scene.closest::<L, KT, KS>(rays, mask, &mut batch);
        let mut occ = vec![false; rays.len()];
        scene.occluded::<L, KT, KS>(rays, mask, &mut occ);
        for (c, chunk) in rays.chunks(L::LANES).enumerate() {
            let p = RayLanes::<L>::load(chunk);
            let packet = scene.closest_packet::<L, KT, KS>(&p, mask);
            let any_packet = scene.occluded_packet::<L, KT, KS>(&p, mask).bitmask();
            for (i, ray) in chunk.iter().enumerate() {
                let (want, any) = brute::<S1, KT, KS>(w, ray, mask);
                let want = bits(want);
                let k = c * L::LANES + i;
                let name = std::any::type_name::<(L, KT, KS)>();
                assert_eq!(
                    bits(packet.lane(i)),
                    want,
                    "packet {name}, mask {mask:x}, {ray:?}"
                );
                assert_eq!(
                    bits(scene.closest_ray::<L, KT, KS>(ray, mask)),
                    want,
                    "single {name}, mask {mask:x}, {ray:?}"
                );
                assert_eq!(bits(batch[k]), want, "slice {name}, {ray:?}");
                assert_eq!(want.is_some(), any, "brute closest vs occluded, {ray:?}");
                assert_eq!(
                    scene.occluded_ray::<L, KT, KS>(ray, mask),
                    any,
                    "occluded {ray:?}"
                );
                assert_eq!((any_packet >> i) & 1 == 1, any, "occluded packet {ray:?}");
                assert_eq!(occ[k], any, "occluded slice {ray:?}");
                hits += want.is_some() as usize;
                if mask == masks[0] {
                    let all = brute_all::<S1, KT, KS>(w, ray, mask);
                    assert_eq!(
                        all_hits::<L, KT, KS>(scene, ray, mask, 3),
                        all,
                        "all hits {name} {ray:?}"
                    );
                }
            }
        }
    }
    // Every hit of each ray of the slice, three slots each (a mask per ray when there are
    // several): brute force's first three, complete when it has no more.
    let per_ray: Vec<u32> = (0..rays.len()).map(|k| masks[k % masks.len()]).collect();
    let mut out = vec![Hit::default(); 3 * rays.len()];
    let mut found = vec![
        octoray::tree::AllHits {
            stored: 9,
            complete: false
        };
        rays.len()
    ];
    scene.all_hits::<L, KT, KS>(rays, &per_ray[..], &mut out, &mut found);
    for (k, ray) in rays.iter().enumerate() {
        let all = brute_all::<S1, KT, KS>(w, ray, per_ray[k]);
        let f = found[k];
        assert_eq!(
            &out[3 * k..3 * k + f.stored],
            &all[..all.len().min(3)],
            "all hits slice {ray:?}"
        );
        assert_eq!(f.complete, all.len() <= 3, "all hits slice {ray:?}");
    }
    // A mask per ray: packets mixing masks, slices too, each ray as brute force under its own.
    if masks.len() > 1 {
        let per_ray: Vec<u32> = (0..rays.len())
            .map(|k| masks[(k * 7 / 3) % masks.len()])
            .collect();
        let mut batch = vec![None; rays.len()];
        scene.closest::<L, KT, KS>(rays, &per_ray[..], &mut batch);
        let mut occ = vec![false; rays.len()];
        scene.occluded::<L, KT, KS>(rays, &per_ray[..], &mut occ);
        for (c, chunk) in rays.chunks(L::LANES).enumerate() {
            let p = RayLanes::<L>::load(chunk);
            let lanes: Vec<u32> = (0..L::LANES)
                .map(|i| per_ray.get(c * L::LANES + i).copied().unwrap_or(0))
                .collect();
            let packet = scene.closest_packet::<L, KT, KS>(&p, &lanes[..]);
            let any_packet = scene.occluded_packet::<L, KT, KS>(&p, &lanes[..]).bitmask();
            for (i, ray) in chunk.iter().enumerate() {
                let k = c * L::LANES + i;
                let (want, any) = brute::<S1, KT, KS>(w, ray, per_ray[k]);
                let want = bits(want);
                assert_eq!(bits(packet.lane(i)), want, "per-lane masks, {ray:?}");
                assert_eq!(bits(batch[k]), want, "per-ray masks, slice, {ray:?}");
                assert_eq!((any_packet >> i) & 1 == 1, any, "per-lane masks, occluded");
                assert_eq!(occ[k], any, "per-ray masks, occluded slice, {ray:?}");
            }
        }
    }
    hits
}

/// Every hit of `ray` through the scene, `cap` at a time.
fn all_hits<L: Lanes, KT: Kernel<L>, KS: Kernel<L, Prim = PackedSphere>>(
    scene: SceneRef<'_, KT::Prim, PackedSphere>,
    ray: &Ray,
    mask: u32,
    cap: usize,
) -> Vec<Hit> {
    let (mut got, mut page, mut after) = (Vec::new(), vec![Hit::default(); cap], None);
    loop {
        let found = scene.all_hits_ray::<L, KT, KS>(ray, mask, after, &mut page);
        got.extend_from_slice(&page[..found.stored]);
        if found.complete {
            return got;
        }
        after = Some(page[cap - 1]);
    }
}

/// A packet's ray masks must be one per lane, a slice's one per ray.
#[test]
#[should_panic(expected = "7 ray masks for 8 rays")]
fn ray_masks_of_the_wrong_length_panic() {
    let (w, rays) = world(3, pack_vertex);
    let scene = w.scene();
    let p = RayLanes::<f32x8>::load(&rays[..8]);
    scene
        .as_ref()
        .closest_packet::<f32x8, Watertight, StableSphere>(&p, &[!0u32; 7][..]);
}

/// A random placement: identity, rigid, scaled (uniform, non-uniform, mirrored), sheared, nearly
/// singular, or a raw world → object matrix.
fn transform(rng: &mut Rng, s: f32) -> Transform {
    let rot = Quat::from_axis_angle(rng.vec3(1.0).normalize_or(Vec3::X), rng.range(-3.2, 3.2));
    let shift = rng.vec3(3.0 * s);
    let affine = match rng.next_u64() % 8 {
        0 => return Transform::IDENTITY,
        1 => Affine3A::from_rotation_translation(rot, shift),
        2 => Affine3A::from_scale_rotation_translation(
            Vec3::splat(10f32.powf(rng.range(-2.0, 2.0))),
            rot,
            shift,
        ),
        3 => Affine3A::from_scale_rotation_translation(
            Vec3::new(
                rng.range(0.05, 20.0),
                rng.range(0.05, 20.0),
                rng.range(0.05, 20.0),
            ),
            rot,
            shift,
        ),
        // Mirrored.
        4 => Affine3A::from_scale_rotation_translation(
            Vec3::new(
                -rng.range(0.5, 2.0),
                rng.range(0.5, 2.0),
                rng.range(0.5, 2.0),
            ),
            rot,
            shift,
        ),
        // Sheared.
        5 => Affine3A::from_cols(
            Vec3::new(1.0, rng.range(-2.0, 2.0), 0.0).into(),
            Vec3::new(0.0, 1.0, rng.range(-2.0, 2.0)).into(),
            Vec3::new(rng.range(-2.0, 2.0), 0.0, 1.0).into(),
            shift.into(),
        ),
        // Nearly singular: one axis squashed by up to 10⁻⁵ (condition numbers past the top
        // level's bound too).
        6 => Affine3A::from_scale_rotation_translation(
            Vec3::new(1.0, 1.0, 10f32.powf(rng.range(-5.0, -1.0))),
            rot,
            shift,
        ),
        // A raw world → object matrix, taken as it is.
        _ => {
            let mut t = Transform::IDENTITY;
            for row in &mut t.rows {
                for x in row.iter_mut() {
                    *x = rng.range(-2.0, 2.0);
                }
            }
            return t;
        }
    };
    Transform::placing(affine).unwrap_or(Transform::IDENTITY)
}

/// A small random mesh near the origin of object space.
fn mesh(rng: &mut Rng, s: f32) -> Vec<[Vec3; 3]> {
    let n = 1 + rng.below(40) as usize;
    let c = rng.vec3(s * 0.3);
    (0..n)
        .map(|_| {
            let a = c + rng.vec3(s * 0.5);
            [a, a + rng.vec3(s * 0.3), a + rng.vec3(s * 0.3)]
        })
        .collect()
}

/// A random world (triangles packed by `pack`), and rays aimed at its instances' world points.
pub(crate) fn world<T: Primitive + Sync>(
    seed: u64,
    pack: fn(&[[Vec3; 3]]) -> Vec<T>,
) -> (World<T>, Vec<Ray>) {
    let mut rng = Rng(seed);
    let s = 10f32.powf(rng.range(-2.0, 2.0));
    let n_geoms = 1 + rng.below(5) as usize;
    let mut geoms = Vec::new();
    let mut local: Vec<Vec<Vec3>> = Vec::new();
    for _ in 0..n_geoms {
        let mask = if rng.below(3) == 0 {
            1 << rng.below(4)
        } else {
            u32::MAX
        };
        if rng.below(3) == 0 {
            let sp: Vec<PackedSphere> = (0..1 + rng.below(20))
                .map(|_| PackedSphere::new(rng.vec3(s * 0.5), s * rng.range(0.01, 0.2)))
                .collect();
            local.push(sp.iter().map(|p| Vec3::from(p.center)).collect());
            geoms.push((Geom::Spheres(sp), mask));
        } else {
            let m = mesh(&mut rng, s);
            local.push(m.iter().map(|t| (t[0] + t[1] + t[2]) / 3.0).collect());
            // Sometimes a duplicate triangle, for ties within a geometry.
            geoms.push((Geom::Tris(pack(&m)), mask));
        }
    }
    // World points of each geometry set or group, in the space that places it.
    let spheres = |g: &Geom<T>| matches!(g, Geom::Spheres(_));
    let place = |rng: &mut Rng,
                 groups: &[Vec<Place>],
                 group_points: &[Vec<Vec3>],
                 k: usize,
                 levels: &[usize],
                 max_levels: usize,
                 prev: Option<&Place>| {
        let usable: Vec<usize> = (0..groups.len())
            .filter(|&g| levels[g] < max_levels)
            .collect();
        // Now and then a group; else one geometry, or every geometry of its kind.
        let target = if !usable.is_empty() && rng.below(3) == 0 {
            Target::Group(usable[rng.below(usable.len() as u64) as usize])
        } else {
            let first = rng.below(n_geoms as u64) as usize;
            Target::Geoms(if rng.below(3) == 0 {
                (0..n_geoms)
                    .filter(|&g| spheres(&geoms[g].0) == spheres(&geoms[first].0))
                    .map(|g| g as u32)
                    .collect()
            } else {
                vec![first as u32]
            })
        };
        // Now and then the same placement twice: ties across instances.
        let transform = match prev {
            Some(p) if k > 0 && rng.below(6) == 0 => p.transform,
            _ => transform(rng, s),
        };
        let mask = if rng.below(4) == 0 {
            1 << rng.below(4)
        } else {
            u32::MAX
        };
        // Points of what it places, mapped back (approximately).
        let mut points = Vec::new();
        if let Some(inv) = inverse_affine(&transform) {
            let local: Vec<Vec3> = match &target {
                Target::Geoms(set) => set
                    .iter()
                    .flat_map(|&g| local[g as usize].clone())
                    .collect(),
                Target::Group(g) => group_points[*g].clone(),
            };
            points.extend(local.iter().map(|p| inv.transform_point3(*p)));
        }
        (
            Place {
                target,
                transform,
                mask,
            },
            points,
        )
    };
    // Now and then groups (each may hold earlier ones, up to the deepest paths allowed).
    let mut groups: Vec<Vec<Place>> = Vec::new();
    let mut group_points: Vec<Vec<Vec3>> = Vec::new();
    let mut levels: Vec<usize> = Vec::new();
    let max = octoray::scene::MAX_INSTANCE_LEVELS as usize;
    if rng.below(2) == 0 {
        for _ in 0..1 + rng.below(4) {
            let mut places: Vec<Place> = Vec::new();
            let mut points = Vec::new();
            let mut depth = 0;
            for k in 0..1 + rng.below(5) as usize {
                let (p, pts) = place(
                    &mut rng,
                    &groups,
                    &group_points,
                    k,
                    &levels,
                    max - 1,
                    places.last(),
                );
                if let Target::Group(c) = p.target {
                    depth = depth.max(levels[c]);
                }
                points.extend(pts);
                places.push(p);
            }
            // Keep the points a handful (aiming only).
            points.truncate(64);
            groups.push(places);
            group_points.push(points);
            levels.push(depth + 1);
        }
    }
    // Mostly a few instances; now and then enough for a top-level tree of several levels.
    let most = if rng.below(3) == 0 { 150 } else { 12 };
    let n_inst = 1 + rng.below(most) as usize;
    let mut insts: Vec<Place> = Vec::new();
    let mut targets = Vec::new();
    for k in 0..n_inst {
        let (p, pts) = place(
            &mut rng,
            &groups,
            &group_points,
            k,
            &levels,
            max,
            insts.last(),
        );
        targets.extend(pts);
        insts.push(p);
    }
    if targets.is_empty() {
        targets.push(Vec3::ZERO);
    }
    let mut rays = Vec::new();
    let mut origin = rng.vec3(4.0 * s);
    for i in 0..64 {
        if i % 8 == 0 {
            origin = rng.vec3(4.0 * s);
        }
        let target = targets[rng.below(targets.len() as u64) as usize];
        let dir = match rng.below(8) {
            0 => rng.vec3(1.0),
            1 => Vec3::new(0.0, -0.0, 1.0),
            2 => Vec3::new(f32::NAN, 1.0, 0.0),
            3 => Vec3::ZERO,
            _ => target - origin,
        };
        let (t_min, t_max) = match rng.below(4) {
            0 => (rng.range(0.0, 0.5), rng.range(0.5, 2.0)),
            _ => (0.0, f32::INFINITY),
        };
        rays.push(Ray::with_range(origin, dir, t_min, t_max));
    }
    rays.extend(testkit::rays::coherent_rays(
        &mut rng,
        &targets,
        Vec3::ZERO,
        s,
        4,
    ));
    (
        World {
            geoms,
            groups,
            insts,
            banned: None,
        },
        rays,
    )
}

/// A world of overlapping instances of level-spanning meshes (and a sphere set): what partial
/// re-braiding opens into parts. Meshes of hundreds of triangles scattered over one region,
/// placed several times each by rotations about it, scales near 1, mirrors and the identity,
/// and one group placing two of them (a group's instance is never opened); rays aimed at their
/// world points.
pub(crate) fn overlapping_world(seed: u64) -> (World<VertexTriangle>, Vec<Ray>) {
    let mut rng = Rng(seed);
    let s = 10f32.powf(rng.range(-1.0, 1.0));
    let mut geoms = Vec::new();
    let mut local: Vec<Vec<Vec3>> = Vec::new();
    for _ in 0..3 {
        let m: Vec<[Vec3; 3]> = (0..300 + rng.below(500))
            .map(|_| {
                let a = rng.vec3(s);
                [a, a + rng.vec3(s * 0.1), a + rng.vec3(s * 0.1)]
            })
            .collect();
        local.push(m.iter().map(|t| (t[0] + t[1] + t[2]) / 3.0).collect());
        geoms.push((Geom::Tris(pack_vertex(&m)), u32::MAX));
    }
    let sp: Vec<PackedSphere> = (0..200)
        .map(|_| PackedSphere::new(rng.vec3(s), s * rng.range(0.005, 0.05)))
        .collect();
    local.push(sp.iter().map(|p| Vec3::from(p.center)).collect());
    geoms.push((Geom::Spheres(sp), u32::MAX));
    let place = |rng: &mut Rng, g: u32| {
        let rot = Quat::from_axis_angle(rng.vec3(1.0).normalize_or(Vec3::X), rng.range(-3.2, 3.2));
        let scale = Vec3::new(
            rng.range(0.7, 1.3) * if rng.below(4) == 0 { -1.0 } else { 1.0 },
            rng.range(0.7, 1.3),
            rng.range(0.7, 1.3),
        );
        let transform = if rng.below(3) == 0 {
            Transform::IDENTITY
        } else {
            let a = Affine3A::from_scale_rotation_translation(scale, rot, rng.vec3(0.1 * s));
            Transform::placing(a).unwrap_or(Transform::IDENTITY)
        };
        Place {
            target: Target::Geoms(vec![g]),
            transform,
            mask: if rng.below(4) == 0 { 1 } else { u32::MAX },
        }
    };
    let mut insts: Vec<Place> = (0..6 + rng.below(6))
        .map(|k| place(&mut rng, (k % 4) as u32))
        .collect();
    let group = vec![place(&mut rng, 0), place(&mut rng, 1)];
    insts.push(Place {
        target: Target::Group(0),
        transform: Transform::IDENTITY,
        mask: u32::MAX,
    });
    let mut targets = Vec::new();
    for i in &insts {
        if let (Target::Geoms(g), Some(inv)) = (&i.target, inverse_affine(&i.transform)) {
            let pts = &local[g[0] as usize];
            targets.extend(pts.iter().step_by(25).map(|p| inv.transform_point3(*p)));
        }
    }
    let mut rays: Vec<Ray> = (0..48)
        .map(|_| {
            let origin = rng.vec3(4.0 * s);
            let target = targets[rng.below(targets.len() as u64) as usize];
            Ray::new(origin, target - origin)
        })
        .collect();
    rays.extend(testkit::rays::coherent_rays(
        &mut rng,
        &targets,
        Vec3::ZERO,
        s,
        4,
    ));
    (
        World {
            geoms,
            groups: vec![group],
            insts,
            banned: None,
        },
        rays,
    )
}

/// Overlapping instances of level-spanning meshes are entered by parts (more parts than
/// instances in the top-level tree), and every query still answers as brute force.
#[test]
fn overlapping_instances_are_entered_by_parts() {
    let mut hits = 0;
    for seed in 0..6 {
        let (w, rays) = overlapping_world(seed);
        let scene = w.scene();
        let r = scene.as_ref();
        let parts = r.world().top.ids().iter().filter(|&&k| k != PAD).count();
        assert!(
            parts > 2 * w.insts.len(),
            "seed {seed}: {parts} parts for {} instances: nothing was opened",
            w.insts.len()
        );
        hits += check::<f32x8, f32, Watertight, StableSphere>(&w, r, &rays, &MASKS);
        hits += check::<f32x16, f32, Watertight, StableSphere>(&w, r, &rays, &MASKS[..1]);
        // Stored and read back, the parts validate and answer alike.
        let stored = Stored::of(&scene.parts());
        let back = SceneRef::<VertexTriangle, PackedSphere>::new(stored.parts()).unwrap();
        check::<f32x8, f32, Watertight, StableSphere>(&w, back, &rays, &MASKS[..1]);
    }
    assert!(hits > 500, "only {hits} hits: the test would not test much");
}

/// The object → world map of a transform, in f32 (for aiming rays only).
fn inverse_affine(t: &Transform) -> Option<Affine3A> {
    let r = &t.rows;
    let a = Affine3A::from_cols(
        Vec3::new(r[0][0], r[1][0], r[2][0]).into(),
        Vec3::new(r[0][1], r[1][1], r[2][1]).into(),
        Vec3::new(r[0][2], r[1][2], r[2][2]).into(),
        Vec3::new(r[0][3], r[1][3], r[2][3]).into(),
    );
    let inv = a.inverse();
    inv.is_finite().then_some(inv)
}

const MASKS: [u32; 3] = [u32::MAX, 1, 6];

pub(crate) fn pack_vertex(t: &[[Vec3; 3]]) -> Vec<VertexTriangle> {
    t.iter()
        .map(|t| VertexTriangle::new(t[0], t[1], t[2]))
        .collect()
}

fn pack_packed(t: &[[Vec3; 3]]) -> Vec<PackedTriangle> {
    t.iter()
        .map(|t| PackedTriangle::new(t[0], t[1], t[2]))
        .collect()
}

fn scene_case(seed: u64) -> usize {
    let (w, rays) = world(seed, pack_vertex);
    // Half the worlds with spatial splits in their geometries' trees.
    let scene = w.scene_with(if seed % 2 == 1 {
        BuildOptions::SPATIAL
    } else {
        BuildOptions::BINNED
    });
    let r = scene.as_ref();
    let mut hits = check::<f32x8, f32, Watertight, StableSphere>(&w, r, &rays, &MASKS);
    hits += check::<f32x16, f32, Watertight, StableSphere>(&w, r, &rays, &MASKS[..1]);
    hits += check::<f64x4, f64, Watertight, StableSphere>(&w, r, &rays, &MASKS[..1]);
    // The naive sphere tier is not sound far from a sphere (its contract): its false hits there
    // lie outside every box, so no tree reports them; the squashed instances here make such
    // rays. The standard triangle tier with the stable spheres, then.
    let (w, rays) = world(seed ^ 0x9e37, pack_packed);
    let scene = w.scene();
    hits += check::<f32x8, f32, MollerTrumbore, StableSphere>(&w, scene.as_ref(), &rays, &MASKS);
    hits
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(40))]
    #[test]
    fn scene_queries_equal_brute_force_over_instanced_primitives(seed in any::<u64>()) {
        scene_case(seed);
    }
}

#[test]
fn many_scene_hits_are_checked() {
    let hits: usize = (0..24).map(|s| scene_case(s * 7919)).sum();
    assert!(
        hits > 1000,
        "only {hits} hits: the suite would not test much"
    );
    // Hits through groups, by path length: the suite's worlds reach every level.
    let mut by_len = [0usize; octoray::scene::MAX_INSTANCE_LEVELS as usize + 1];
    for seed in 0..24 {
        let (w, rays) = world(seed * 7919, pack_vertex);
        let scene = w.scene();
        let r = scene.as_ref();
        for ray in &rays {
            if let Some(h) = r.closest_ray::<f32x8, Watertight, StableSphere>(ray, !0) {
                by_len[r.instance_path(h.inst).unwrap().as_slice().len()] += 1;
            }
        }
    }
    assert!(
        by_len[2] > 100 && by_len[3] > 20 && by_len[4] > 0,
        "hits by path length {by_len:?}: nesting would not be tested much"
    );
}

/// The tie rule across instances: two instances of one mesh at one place report the lower.
#[test]
fn equal_t_across_instances_goes_to_the_lower_instance() {
    let tri = [
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    let mut s = Scene::<VertexTriangle, PackedSphere>::new();
    let g = s.add_triangles(&pack_vertex(&[tri, tri])).unwrap();
    let shift = Transform::placing(Affine3A::from_translation(Vec3::new(0.0, 0.0, 1.0))).unwrap();
    s.add_instance(&[g], shift, u32::MAX);
    s.add_instance(&[g], Transform::IDENTITY, 2);
    s.add_instance(&[g], Transform::IDENTITY, u32::MAX);
    s.commit().expect("commit");
    let ray = Ray::new(Vec3::new(0.1, 0.0, -2.0), Vec3::Z);
    let h = s
        .as_ref()
        .closest_ray::<f32x8, Watertight, StableSphere>(&ray, u32::MAX)
        .unwrap();
    assert_eq!((h.t, h.prim, h.geom, h.inst), (2.0, 0, 0, 1));
    // Mask 1 skips instance 1 (mask 2): instance 2 wins at the same t.
    let h = s
        .as_ref()
        .closest_ray::<f32x8, Watertight, StableSphere>(&ray, 1)
        .unwrap();
    assert_eq!((h.t, h.inst), (2.0, 2));
    // A geometry mask that shares no bit with the query hides every instance of it.
    s.set_geometry_mask(g, 4);
    assert!(!s
        .as_ref()
        .occluded_ray::<f32x8, Watertight, StableSphere>(&ray, 3));
}

/// A filter sees geometry and instance, and rejecting one instance's hits equals brute force
/// without that instance.
/// A `Tracer` answers what the `Trace` calls it fixes the tiers and width of answer, bit for bit,
/// on every query kind, with masks and with a filter.
#[test]
fn tracer_answers_are_the_trace_calls() {
    let mut hits = 0;
    for seed in 0..8u64 {
        let (w, rays) = world(seed * 17 + 3, pack_vertex);
        let scene = w.scene();
        let r = scene.as_ref();
        let tracer = Tracer::<f32x8, Watertight, StableSphere>::new(r);
        let copy = tracer;
        assert_eq!(copy.scene().instances().len(), r.instances().len());
        for &mask in &MASKS {
            let (mut a, mut b) = (vec![None; rays.len()], vec![None; rays.len()]);
            tracer.closest(&rays, mask, &mut a);
            r.closest::<f32x8, Watertight, StableSphere>(&rays, mask, &mut b);
            assert_eq!(
                a.iter().map(|h| bits(*h)).collect::<Vec<_>>(),
                b.iter().map(|h| bits(*h)).collect::<Vec<_>>()
            );
            let (mut a, mut b) = (vec![false; rays.len()], vec![false; rays.len()]);
            tracer.occluded(&rays, mask, &mut a);
            r.occluded::<f32x8, Watertight, StableSphere>(&rays, mask, &mut b);
            assert_eq!(a, b);
            for chunk in rays.chunks(8) {
                let p = RayLanes::<f32x8>::load(chunk);
                let (x, y) = (
                    tracer.closest_packet(&p, mask),
                    r.closest_packet::<f32x8, Watertight, StableSphere>(&p, mask),
                );
                for i in 0..chunk.len() {
                    assert_eq!(bits(x.lane(i)), bits(y.lane(i)));
                }
                assert_eq!(
                    tracer.occluded_packet(&p, mask).bitmask(),
                    r.occluded_packet::<f32x8, Watertight, StableSphere>(&p, mask)
                        .bitmask()
                );
            }
            for ray in &rays {
                let h = tracer.closest_ray(ray, mask);
                assert_eq!(
                    bits(h),
                    bits(r.closest_ray::<f32x8, Watertight, StableSphere>(ray, mask))
                );
                assert_eq!(tracer.occluded_ray(ray, mask), h.is_some());
                hits += usize::from(h.is_some());
                // A filter that rejects even primitives, through the tracer and the trait.
                let mut odd = |c: &Candidate| c.prim % 2 == 1;
                assert_eq!(
                    bits(tracer.closest_ray_with(ray, mask, &mut dyn_filter(&mut odd))),
                    bits(r.closest_ray_with::<f32x8, Watertight, StableSphere, _>(
                        ray,
                        mask,
                        &mut dyn_filter(&mut odd)
                    ))
                );
            }
        }
    }
    assert!(hits > 100, "{hits}");
}

#[test]
fn filters_see_geometry_and_instance() {
    for seed in 0..16u64 {
        let (w, rays) = world(seed * 31 + 5, pack_vertex);
        let scene = w.scene();
        let r = scene.as_ref();
        let paths = r
            .world()
            .instances
            .last()
            .map_or(0, |i| i.path + r.trees()[i.tree as usize].paths());
        let banned = (seed % u64::from(paths)) as u32;
        let without = World {
            geoms: w.geoms.clone(),
            groups: w.groups.clone(),
            insts: w.insts.clone(),
            banned: Some(banned),
        };
        for (k, ray) in rays.iter().enumerate() {
            let mut seen_ok = true;
            let mut filter = |c: &Candidate| {
                let leaf = r.instance_path(c.inst).map(|p| p.leaf());
                let tree = leaf.map(|k| r.instances()[k as usize].tree);
                seen_ok &= tree.is_some_and(|t| r.members(t).iter().any(|m| m.geom == c.geom))
                    && c.ray == 0;
                c.inst != banned
            };
            let got = r.closest_ray_with::<f32x8, Watertight, StableSphere, _>(
                ray,
                !0,
                &mut dyn_filter(&mut filter),
            );
            let (want, any) = brute::<f32, Watertight, StableSphere>(&without, ray, !0);
            assert_eq!(bits(got), bits(want), "ray {k}");
            let occ = r.occluded_ray_with::<f32x8, Watertight, StableSphere, _>(
                ray,
                !0,
                &mut dyn_filter(&mut |c: &Candidate| c.inst != banned),
            );
            assert_eq!(occ, any, "ray {k}");
            assert!(seen_ok);
        }
        let mut out = vec![None; rays.len()];
        r.closest_with::<f32x8, Watertight, StableSphere, _>(
            &rays,
            !0,
            &mut out,
            &mut dyn_filter(&mut |c: &Candidate| c.inst != banned),
        );
        for (ray, got) in rays.iter().zip(&out) {
            assert_eq!(
                bits(*got),
                bits(brute::<f32, Watertight, StableSphere>(&without, ray, !0).0)
            );
        }
    }
}

/// Refitting a geometry after its vertices moved and moving instances, then committing, gives
/// brute force on the new world.
#[test]
fn refit_and_moved_instances_equal_brute_force() {
    for seed in 0..12u64 {
        let (mut w, rays) = world(seed * 101 + 3, pack_vertex);
        let mut scene = w.scene();
        let mut rng = Rng(seed);
        for (g, (geom, _)) in w.geoms.iter_mut().enumerate() {
            match geom {
                Geom::Tris(p) => {
                    for t in p.iter_mut() {
                        let d = rng.vec3(0.3);
                        let v = [t.v0, t.v1, t.v2].map(Vec3::from);
                        *t = VertexTriangle::new(v[0] + d, v[1] + d, v[2] - d);
                    }
                    scene.refit_triangles(g as u32, p).unwrap();
                }
                Geom::Spheres(p) => {
                    for sp in p.iter_mut() {
                        let r = sp.radius_sq.sqrt() * 1.5;
                        *sp = PackedSphere::new(Vec3::from(sp.center) + rng.vec3(0.3), r);
                    }
                    scene.refit_spheres(g as u32, p).unwrap();
                }
            }
        }
        for (i, inst) in w.insts.iter_mut().enumerate() {
            if rng.below(2) == 0 {
                inst.transform = transform(&mut rng, 1.0);
                scene.set_transform(i as u32, inst.transform);
            }
        }
        for (g, places) in w.groups.iter_mut().enumerate() {
            for (k, inst) in places.iter_mut().enumerate() {
                if rng.below(3) == 0 {
                    inst.transform = transform(&mut rng, 1.0);
                    scene.set_group_transform(g as u32, k as u32, inst.transform);
                }
            }
        }
        scene.commit().expect("commit");
        check::<f32x8, f32, Watertight, StableSphere>(&w, scene.as_ref(), &rays, &MASKS[..1]);
    }
}

#[test]
#[should_panic(expected = "changed since its last commit")]
fn tracing_an_uncommitted_scene_panics() {
    let mut s = Scene::<VertexTriangle, PackedSphere>::new();
    let g = s
        .add_spheres(&[PackedSphere::new(Vec3::ZERO, 1.0)])
        .unwrap();
    s.add_instance(&[g], Transform::IDENTITY, !0);
    let _ = s.as_ref();
}

/// A tree's owned slices.
type Tree = (Vec<octoray::bvh::Bvh8Node>, Vec<[f32; 8]>, Vec<u32>);

/// Owned copies of a scene's slices (what a file would hold).
pub(crate) struct Stored {
    tri: Tree,
    sph: Tree,
    top: Tree,
    geoms: Vec<Geometry>,
    pub(crate) trees: Vec<SceneTree>,
    members: Vec<Member>,
    insts: Vec<Instance>,
    pub(crate) unbounded: Vec<u32>,
}

impl Stored {
    pub(crate) fn of(p: &SceneParts<'_>) -> Self {
        let t = |t: &octoray::scene::TreeParts<'_>| {
            (t.nodes.to_vec(), t.blocks.to_vec(), t.ids.to_vec())
        };
        Self {
            tri: t(&p.triangles),
            sph: t(&p.spheres),
            top: t(&p.top),
            geoms: p.geometries.to_vec(),
            trees: p.trees.to_vec(),
            members: p.members.to_vec(),
            insts: p.instances.to_vec(),
            unbounded: p.unbounded.to_vec(),
        }
    }

    pub(crate) fn parts(&self) -> SceneParts<'_> {
        fn t(t: &Tree) -> octoray::scene::TreeParts<'_> {
            octoray::scene::TreeParts {
                nodes: &t.0,
                blocks: &t.1,
                ids: &t.2,
            }
        }
        SceneParts {
            triangles: t(&self.tri),
            spheres: t(&self.sph),
            geometries: &self.geoms,
            trees: &self.trees,
            members: &self.members,
            instances: &self.insts,
            top: t(&self.top),
            unbounded: &self.unbounded,
        }
    }

    /// Every 32-bit word of every slice, for corruption.
    fn words(&mut self) -> Vec<&mut u32> {
        let mut out: Vec<&mut u32> = Vec::new();
        for t in [&mut self.tri, &mut self.sph, &mut self.top] {
            out.extend(bytemuck::cast_slice_mut::<_, u32>(&mut t.0[..]).iter_mut());
            out.extend(bytemuck::cast_slice_mut::<_, u32>(&mut t.1[..]).iter_mut());
            out.extend(t.2.iter_mut());
        }
        out.extend(bytemuck::cast_slice_mut::<_, u32>(&mut self.geoms[..]).iter_mut());
        out.extend(bytemuck::cast_slice_mut::<_, u32>(&mut self.trees[..]).iter_mut());
        out.extend(bytemuck::cast_slice_mut::<_, u32>(&mut self.members[..]).iter_mut());
        out.extend(bytemuck::cast_slice_mut::<_, u32>(&mut self.insts[..]).iter_mut());
        out.extend(self.unbounded.iter_mut());
        out
    }
}

/// A scene read back from its slices validates and answers the same; corrupted slices are
/// rejected with an error or, when accepted, traced without a panic and with hits in range.
#[test]
fn stored_scenes_validate_and_corrupted_ones_never_panic() {
    for seed in 0..12u64 {
        let (w, rays) = world(seed * 17 + 1, pack_vertex);
        let scene = w.scene();
        let stored = Stored::of(&scene.parts());
        let back = SceneRef::<VertexTriangle, PackedSphere>::new(stored.parts()).unwrap();
        check::<f32x8, f32, Watertight, StableSphere>(&w, back, &rays, &MASKS[..1]);
        let mut rng = Rng(seed);
        for _ in 0..60 {
            let mut bad = Stored::of(&scene.parts());
            {
                let mut words = bad.words();
                for _ in 0..1 + rng.below(3) {
                    let k = rng.below(words.len() as u64) as usize;
                    *words[k] = match rng.below(4) {
                        0 => rng.next_u64() as u32,
                        1 => *words[k] ^ (1 << rng.below(32)),
                        2 => u32::MAX,
                        _ => 0,
                    };
                }
            }
            match SceneRef::<VertexTriangle, PackedSphere>::new(bad.parts()) {
                Err(e) => assert!(!e.to_string().is_empty()),
                Ok(r) => {
                    for ray in &rays {
                        if let Some(h) = r.closest_ray::<f32x8, Watertight, StableSphere>(ray, !0) {
                            let path = r.instance_path(h.inst).expect("a reported path");
                            let inst = &r.instances()[path.leaf() as usize];
                            let tree = &r.trees()[inst.tree as usize];
                            assert!(h.geom < r.geometries().len() as u32);
                            assert!(h.prim < tree.prims());
                            assert!(h.t.is_finite());
                        }
                        r.occluded_ray::<f32x8, Watertight, StableSphere>(ray, !0);
                        // Point queries: in range, a finite distance.
                        if let Some(h) = r.closest_point(ray.origin, f32::INFINITY, !0) {
                            assert!(r.instance_path(h.inst).is_some());
                            assert!(h.geom < r.geometries().len() as u32);
                            assert!(h.dist.is_finite() && h.dist >= 0.0);
                        }
                        let mut near = [octoray::tree::PointHit::default(); 3];
                        r.nearest_within(ray.origin, 1.0, !0, &mut near);
                    }
                    let p = RayLanes::<f32x8>::load(&rays[..8]);
                    r.closest_packet::<f32x8, Watertight, StableSphere>(&p, !0);
                }
            }
        }
    }
}

/// A scene stored as words (`SceneRef::to_words`) reads back in place and answers the same; words
/// of another layout, a changed header word and truncations are refused with `BadWords` or a
/// validation error, never a panic.
#[test]
fn scenes_stored_as_words_read_back_and_bad_words_are_refused() {
    for seed in 0..8u64 {
        let (w, rays) = world(seed * 31 + 5, pack_vertex);
        let scene = w.scene();
        let words = scene.as_ref().to_words();
        let back = SceneRef::<VertexTriangle, PackedSphere>::from_words(&words).unwrap();
        check::<f32x8, f32, Watertight, StableSphere>(&w, back, &rays, &MASKS[..1]);
        assert!(matches!(
            SceneRef::<PackedTriangle, PackedSphere>::from_words(&words),
            Err(SceneError::BadWords(_))
        ));
        // The header: the magic, the layouts' sizes and tags and the 14 section lengths.
        for i in 0..19 {
            for v in [words[i].wrapping_add(1), words[i].wrapping_sub(1), u32::MAX] {
                let mut bad = words.clone();
                bad[i] = v;
                let r = SceneRef::<VertexTriangle, PackedSphere>::from_words(&bad);
                assert!(r.is_err(), "header word {i} = {v}");
            }
        }
        let mut rng = Rng(seed);
        for _ in 0..64 {
            let n = rng.below(words.len() as u64) as usize;
            assert!(SceneRef::<VertexTriangle, PackedSphere>::from_words(&words[..n]).is_err());
        }
    }
}

#[test]
fn malformed_scenes_name_what_is_wrong() {
    let flat = (7..).find(|&seed| world(seed, pack_vertex).0.groups.is_empty());
    let (w, _) = world(flat.unwrap(), pack_vertex);
    let scene = w.scene();
    let mut s = Stored::of(&scene.parts());
    s.insts[0].tree = 1000;
    assert_eq!(
        SceneRef::<VertexTriangle, PackedSphere>::new(s.parts()).unwrap_err(),
        SceneError::BadInstance { inst: 0 }
    );
    let mut s = Stored::of(&scene.parts());
    s.geoms[0].kind = 7;
    assert_eq!(
        SceneRef::<VertexTriangle, PackedSphere>::new(s.parts()).unwrap_err(),
        SceneError::BadKind { at: 0 }
    );
    let mut s = Stored::of(&scene.parts());
    s.members[0].first_prim = 1;
    assert_eq!(
        SceneRef::<VertexTriangle, PackedSphere>::new(s.parts()).unwrap_err(),
        SceneError::BadMembers { tree: 0 }
    );
    let mut s = Stored::of(&scene.parts());
    s.unbounded.push(u32::MAX);
    assert_eq!(
        SceneRef::<VertexTriangle, PackedSphere>::new(s.parts()).unwrap_err(),
        SceneError::BadUnbounded {
            at: s.unbounded.len() - 1
        }
    );
    let mut s = Stored::of(&scene.parts());
    s.insts[0].path = 1;
    assert_eq!(
        SceneRef::<VertexTriangle, PackedSphere>::new(s.parts()).unwrap_err(),
        SceneError::BadInstance { inst: 0 }
    );

    // Groups: a tree of three levels of groups placed in the world.
    let (nested, _) = nested_scene();
    let parts = nested.parts();
    let group = |s: &Stored| {
        s.trees
            .iter()
            .position(|t| t.kind() == octoray::scene::INSTANCES)
            .unwrap()
    };
    let s = Stored::of(&parts);
    let (g0, last) = (group(&s), s.trees.len() - 1);
    assert!(SceneRef::<VertexTriangle, PackedSphere>::new(s.parts()).is_ok());
    // A group's instance placing a tree that does not come before it (a cycle).
    let mut s = Stored::of(&parts);
    let first = words(&s.trees[g0])[FIRST_MEMBER] as usize;
    s.insts[first].tree = g0 as u32;
    assert_eq!(
        SceneRef::<VertexTriangle, PackedSphere>::new(s.parts()).unwrap_err(),
        SceneError::BadInstance { inst: first }
    );
    // Levels, paths, mask and slack are what the instances make them.
    for corrupt in [
        (|t: &mut SceneTree| *word(t, LEVELS) += 1) as fn(&mut SceneTree),
        |t| *word(t, PATHS) += 1,
        |t| *word(t, MASK) ^= 1,
        |t| *word(t, SLACK) = (f32::from_bits(words(t)[SLACK]) * 2.0).to_bits(),
        |t| *word(t, FIRST_UNBOUNDED) += 1,
    ] {
        let mut s = Stored::of(&parts);
        corrupt(&mut s.trees[last]);
        assert_eq!(
            SceneRef::<VertexTriangle, PackedSphere>::new(s.parts()).unwrap_err(),
            SceneError::BadGroup { tree: last },
        );
    }
    // Deeper than MAX_INSTANCE_LEVELS: refused when built, and when stored.
    let mut deep = Scene::<VertexTriangle, PackedSphere>::new();
    let g = deep
        .add_triangles(&pack_vertex(&[[Vec3::X, Vec3::Y, Vec3::Z]]))
        .unwrap();
    let mut below = deep.add_group();
    deep.add_to_group(below, &[g], Transform::IDENTITY, !0);
    for _ in 1..octoray::scene::MAX_INSTANCE_LEVELS {
        let above = deep.add_group();
        deep.place_group(Some(above), below, Transform::IDENTITY, !0);
        below = above;
    }
    deep.place_group(None, below, Transform::IDENTITY, !0);
    assert_eq!(
        deep.commit_on(&octoray::bvh::Sequential),
        Err(octoray::bvh::BvhError::TooManyLevels)
    );
}

/// A scene of nested groups: a 2×2 tile of one triangle pair (a group of two instances), a row
/// of three tiles (a group), and the row placed twice in the world, once mirrored; and the
/// instances the scene should report, by path.
fn nested_scene() -> (Scene<VertexTriangle, PackedSphere>, Vec<[u32; 3]>) {
    let quad = [
        [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
        ],
        [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ],
    ];
    let shift = |x: f32, y: f32| {
        Transform::placing(Affine3A::from_translation(Vec3::new(x, y, 0.0))).unwrap()
    };
    let mut s = Scene::<VertexTriangle, PackedSphere>::new();
    let g = s.add_triangles(&pack_vertex(&quad)).unwrap();
    let tile = s.add_group();
    s.add_to_group(tile, &[g], Transform::IDENTITY, !0);
    s.add_to_group(tile, &[g], shift(1.0, 0.0), !0);
    let row = s.add_group();
    for k in 0..3 {
        s.place_group(Some(row), tile, shift(2.0 * k as f32, 0.0), !0);
    }
    s.place_group(None, row, shift(0.0, 5.0), !0);
    let mirror = Affine3A::from_scale(Vec3::new(1.0, -1.0, 1.0));
    s.place_group(None, row, Transform::placing(mirror).unwrap(), 2);
    s.commit().expect("commit");
    // Path p = 6·world + 2·tile + quad. Stored: the world's instances 0..2, then the groups'
    // in the order made (the tile's 2..4, the row's 4..7).
    let paths = (0..12u32)
        .map(|p| [p / 6, 4 + (p / 2) % 3, 2 + p % 2])
        .collect();
    (s, paths)
}

/// Nested groups: each hit names its instance path, the path reads back as its instances, masks
/// AND down the path, and every query equals brute force over the paths.
#[test]
fn nested_groups_name_their_instance_paths() {
    let (s, paths) = nested_scene();
    let r = s.as_ref();
    for (p, want) in paths.iter().enumerate() {
        assert_eq!(r.instance_path(p as u32).unwrap().as_slice(), want);
    }
    assert_eq!(r.instance_path(12), None);
    assert_eq!(r.paths(), 12);
    for p in 0..12u32 {
        let (world, tile) = (p / 6, (p / 2) % 3);
        let x = 2.0 * tile as f32 + (p % 2) as f32 + 0.25;
        let y = if world == 0 { 5.5 } else { -0.5 };
        let ray = Ray::new(Vec3::new(x, y, -1.0), Vec3::Z);
        let h = r
            .closest_ray::<f32x8, Watertight, StableSphere>(&ray, !0)
            .unwrap();
        assert_eq!((h.t, h.geom, h.inst), (1.0, 0, p), "{ray:?}");
        // The mirrored row has mask 2: a query of mask 1 misses it, and only it.
        let masked = r.closest_ray::<f32x8, Watertight, StableSphere>(&ray, 1);
        assert_eq!(masked.is_some(), world == 0);
    }
}

/// The transform's contract: the identity keeps the ray's bits; a placed transform maps a point
/// of the object to within rounding of where the world ray meets it.
#[test]
fn transforms_carry_rays_into_object_space() {
    let ray = Ray::with_range(
        Vec3::new(-0.0, 1.0, 2.0),
        Vec3::new(0.0, -0.0, 1.0),
        0.5,
        9.0,
    );
    let same = Transform::IDENTITY.apply(&ray);
    assert_eq!(
        [same.origin.x, same.dir.y].map(f32::to_bits),
        [ray.origin.x, ray.dir.y].map(f32::to_bits)
    );
    let place = Affine3A::from_scale_rotation_translation(
        Vec3::new(2.0, 0.5, -3.0),
        Quat::from_rotation_y(0.7),
        Vec3::new(10.0, -4.0, 1.0),
    );
    let t = Transform::placing(place).unwrap();
    let obj = t.apply(&ray);
    assert_eq!((obj.t_min, obj.t_max), (0.5, 9.0));
    for k in [0.5f32, 1.0, 4.0] {
        let back = place.transform_point3(obj.at(k));
        assert!(
            (back - ray.at(k)).length() < 1e-5,
            "{back} vs {}",
            ray.at(k)
        );
    }
    assert!(Transform::placing(Affine3A::from_scale(Vec3::new(1.0, 0.0, 1.0))).is_none());
    assert!(t.condition().unwrap() >= 1.0);
}

/// A part naming no node of its instance's tree (or a group's instance entered below its root)
/// is refused, naming the level and the slot.
#[test]
fn parts_naming_no_node_are_refused() {
    let (w, _) = overlapping_world(3);
    let scene = w.scene();
    let parts = scene.parts();
    let words = <octoray::scene::InstanceBox as Primitive>::WORDS;
    // Word 6 of an instance box is its node (the field after the two corners).
    fn node_word(s: &mut Stored, words: usize, slot: usize) -> &mut f32 {
        &mut s.top.1[slot / 8 * words + 6][slot % 8]
    }
    let world_slots = scene.as_ref().world().top.ids().len();
    let ids = &parts.top.ids[..world_slots];
    let slot = (0..world_slots)
        .find(|&k| ids[k] != PAD && matches!(w.insts[ids[k] as usize].target, Target::Geoms(_)))
        .unwrap();
    let mut s = Stored::of(&parts);
    *node_word(&mut s, words, slot) = f32::from_bits(1 << 30);
    assert_eq!(
        SceneRef::<VertexTriangle, PackedSphere>::new(s.parts()).unwrap_err(),
        SceneError::BadPart { level: None, slot },
    );
    // The world's instance of the group is one part (its root).
    let slot = (0..world_slots)
        .find(|&k| ids[k] != PAD && matches!(w.insts[ids[k] as usize].target, Target::Group(_)))
        .unwrap();
    let mut s = Stored::of(&parts);
    *node_word(&mut s, words, slot) = f32::from_bits(1);
    assert_eq!(
        SceneRef::<VertexTriangle, PackedSphere>::new(s.parts()).unwrap_err(),
        SceneError::BadPart { level: None, slot },
    );
    // The group's tree follows the world's in the top slices.
    let group = parts
        .trees
        .iter()
        .position(|t| t.kind() == octoray::scene::INSTANCES)
        .unwrap();
    let g_slot = (world_slots..parts.top.ids.len())
        .find(|&k| parts.top.ids[k] != PAD)
        .unwrap();
    let mut s = Stored::of(&parts);
    *node_word(&mut s, words, g_slot) = f32::from_bits(1 << 30);
    assert_eq!(
        SceneRef::<VertexTriangle, PackedSphere>::new(s.parts()).unwrap_err(),
        SceneError::BadPart {
            level: Some(group),
            slot: g_slot - world_slots,
        },
    );
}
