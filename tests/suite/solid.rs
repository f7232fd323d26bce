//! Queries beyond the first hit: every hit along a ray equals brute force bit for bit (binned and
//! spatial-split trees, every tier, buffers too small for the answer), and the crossing rule's
//! counts, containment and winding numbers are exactly right on closed meshes built from
//! voxels on a coarse grid (the worst case for shared edges and vertices: points and rays on
//! faces, along edges, through vertices), against an oracle that knows the answer exactly.
#![cfg(feature = "triangle")]
use octoray::bvh::{BuildOptions, Bvh8, Sequential, Solid, SolidError};
use octoray::glam::Vec3;
use octoray::hit::Hit;
use octoray::kernels::{Exact, ExactCrossing, Kernel, MollerTrumbore, Watertight};
use octoray::prim::{PackedTriangle, Primitive, Ray, VertexTriangle};
use octoray::tree::{
    all_hits, all_hits_ray, closest_point, contains, crossings_ray, hit_order, signed_distance,
    winding_number, AllHits,
};
use octoray::{f32x16, f32x8};
use octoray_testkit::cases::proptest_config;
use proptest::prelude::*;

/// A set of unit voxels on an `N³` grid, placed at `origin + scale·cell`.
#[derive(Clone, Debug)]
pub(crate) struct Voxels {
    n: i32,
    filled: Vec<bool>,
    origin: Vec3,
    scale: f32,
}

impl Voxels {
    fn at(&self, c: [i32; 3]) -> bool {
        c.iter().all(|&x| (0..self.n).contains(&x))
            && self.filled[((c[2] * self.n + c[1]) * self.n + c[0]) as usize]
    }

    /// The grid point `g` (integer or quarter-integer coordinates) in space, exactly (the
    /// scale is a power of two and the origin a coarse dyadic).
    pub(crate) fn point(&self, g: [f32; 3]) -> Vec3 {
        self.origin + self.scale * Vec3::from(g)
    }

    /// Is the grid point `g`, moved by `(ε, ε², ε³)`, inside? Its cell is `floor(g)` whether or
    /// not `g` lies on a face, an edge or a vertex.
    pub(crate) fn oracle(&self, g: [f32; 3]) -> bool {
        self.at(g.map(|x| x.floor() as i32))
    }

    /// The boundary: each face between a filled and an empty cell as two triangles (split along
    /// the diagonal `split` picks) or four around its centre, normals out.
    pub(crate) fn surface(&self, split: &[u8]) -> Vec<VertexTriangle> {
        let mut tris = Vec::new();
        let mut k = 0;
        for z in 0..self.n {
            for y in 0..self.n {
                for x in 0..self.n {
                    let c = [x, y, z];
                    if !self.at(c) {
                        continue;
                    }
                    for axis in 0..3 {
                        for dir in [-1, 1] {
                            let mut nb = c;
                            nb[axis] += dir;
                            if self.at(nb) {
                                continue;
                            }
                            let quad = self.face(c, axis, dir);
                            let how = split.get(k % split.len().max(1)).copied().unwrap_or(0);
                            k += 1;
                            self.push_quad(&mut tris, quad, how);
                        }
                    }
                }
            }
        }
        tris
    }

    /// The four corners of cell `c`'s face on side `dir` of `axis`, counter-clockwise seen from
    /// outside.
    fn face(&self, c: [i32; 3], axis: usize, dir: i32) -> [[f32; 3]; 4] {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        let corner = |du: i32, dv: i32| {
            let mut g = c.map(|x| x as f32);
            g[axis] += if dir > 0 { 1.0 } else { 0.0 };
            g[u] += du as f32;
            g[v] += dv as f32;
            g
        };
        let ccw = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)];
        if dir > 0 {
            ccw
        } else {
            [ccw[0], ccw[3], ccw[2], ccw[1]]
        }
    }

    fn push_quad(&self, tris: &mut Vec<VertexTriangle>, q: [[f32; 3]; 4], how: u8) {
        let p = q.map(|g| self.point(g));
        match how % 3 {
            0 => {
                tris.push(VertexTriangle::new(p[0], p[1], p[2]));
                tris.push(VertexTriangle::new(p[0], p[2], p[3]));
            }
            1 => {
                tris.push(VertexTriangle::new(p[1], p[2], p[3]));
                tris.push(VertexTriangle::new(p[1], p[3], p[0]));
            }
            _ => {
                let mid: [f32; 3] = core::array::from_fn(|i| (q[0][i] + q[2][i]) / 2.0);
                let m = self.point(mid);
                for i in 0..4 {
                    tris.push(VertexTriangle::new(m, p[i], p[(i + 1) % 4]));
                }
            }
        }
    }
}

pub(crate) fn voxels() -> impl Strategy<Value = (Voxels, Vec<u8>)> {
    (2i32..=5).prop_flat_map(|n| {
        let cells = (n * n * n) as usize;
        (
            prop::collection::vec(prop::bool::weighted(0.45), cells),
            prop::collection::vec(0u8..3, 1..16),
            -8i32..8,
            -2i32..2,
        )
            .prop_map(move |(filled, split, off, sc)| {
                let scale = 2f32.powi(sc);
                let origin = Vec3::new(off as f32 * 0.75, -off as f32 * 0.5, off as f32 * 0.25);
                (
                    Voxels {
                        n,
                        filled,
                        origin,
                        scale,
                    },
                    split,
                )
            })
    })
}

/// Grid points in quarter cells around the grid: on faces, edges and vertices a quarter of the
/// time each coordinate.
pub(crate) fn grid_points(n: i32) -> impl Strategy<Value = [f32; 3]> {
    prop::array::uniform3(-6..=4 * n + 2).prop_map(|q| q.map(|x| x as f32 / 4.0))
}

/// Both tree kinds: binned (each triangle once) and spatial splits (triangles in several
/// leaves).
pub(crate) fn trees(tris: &[VertexTriangle]) -> [Bvh8<VertexTriangle>; 2] {
    [BuildOptions::BINNED, BuildOptions::SPATIAL]
        .map(|o| Bvh8::try_build_options(tris, o, &Sequential).expect("build"))
}

proptest! {
    #![proptest_config(proptest_config(96))]

    #[test]
    fn containment_and_winding_are_exact_on_voxel_solids(
        (vox, split) in voxels(),
        points in prop::collection::vec(grid_points(5), 64),
    ) {
        let tris = vox.surface(&split);
        for bvh in trees(&tris) {
            let solid = Solid::new(bvh.as_ref(), &tris).expect("a voxel surface is closed");
            for g in &points {
                let p = vox.point(*g);
                let want = vox.oracle(*g);
                prop_assert_eq!(contains::<f32x8>(solid, p), want, "{:?} at {:?}", vox, g);
                prop_assert_eq!(winding_number::<f32x8>(solid, p), i32::from(want), "{:?}", g);
                let sd = signed_distance::<f32x8>(solid, p);
                let d = closest_point(solid.bvh(), p, f32::INFINITY).map_or(f32::INFINITY, |h| h.dist);
                prop_assert_eq!(sd.to_bits(), if want { -d } else { d }.to_bits(), "{:?}", g);
            }
        }
    }

    #[test]
    fn crossing_parity_is_exact_for_any_direction(
        (vox, split) in voxels(),
        rays in prop::collection::vec((grid_points(5), prop::array::uniform3(-4i32..=4), 1u32..8), 48),
    ) {
        // Directions and lengths on the grid too: the segment's far end is a grid point, and
        // the rays run along faces and edges and through vertices.
        let tris = vox.surface(&split);
        for bvh in trees(&tris) {
            for (g, d, len) in &rays {
                let dg = d.map(|x| x as f32 / 4.0);
                if dg == [0.0; 3] {
                    continue;
                }
                let end: [f32; 3] = core::array::from_fn(|i| g[i] + *len as f32 * dg[i]);
                let dir = Vec3::from(dg) * vox.scale;
                let ray = Ray::with_range(vox.point(*g), dir, 0.0, *len as f32);
                let n = crossings_ray::<f32x8>(bvh.as_ref(), &ray);
                prop_assert_eq!(n % 2 == 1, vox.oracle(*g) != vox.oracle(end), "{:?} {:?}", g, dg);
            }
        }
    }

    #[test]
    fn all_hits_equal_brute_force_bit_for_bit(
        (vox, split) in voxels(),
        rays in prop::collection::vec((grid_points(5), prop::array::uniform3(-9i32..=9)), 24),
        cap in 1usize..6,
    ) {
        let tris = vox.surface(&split);
        let packed: Vec<PackedTriangle> = tris
            .iter()
            .map(|t| PackedTriangle::new(t.v0.into(), t.v1.into(), t.v2.into()))
            .collect();
        let [binned, spatial] = trees(&tris);
        let [pb, ps] = [BuildOptions::BINNED, BuildOptions::SPATIAL]
            .map(|o| Bvh8::try_build_options(&packed, o, &Sequential).expect("build"));
        for (g, d) in &rays {
            let dir = Vec3::from(d.map(|x| x as f32 / 7.0 + 0.01));
            let ray = Ray::new(vox.point(*g), dir);
            for bvh in [&binned, &spatial] {
                check_all_hits::<f32x8, Exact>(bvh, &tris, &ray, cap)?;
                check_all_hits::<f32x16, Watertight>(bvh, &tris, &ray, cap)?;
                check_all_hits::<f32x8, ExactCrossing>(bvh, &tris, &ray, cap)?;
            }
            for bvh in [&pb, &ps] {
                check_all_hits::<f32x8, MollerTrumbore>(bvh, &packed, &ray, cap)?;
            }
        }
        // The slice call (packets where rays share an octant: here rays from one corner, and
        // the mixed rays above) gives each ray's first page.
        let corner = vox.point([-1.0, -1.0, -1.0]);
        let mut all: Vec<Ray> = rays
            .iter()
            .map(|(g, _)| Ray::new(corner, vox.point(*g) - corner))
            .collect();
        all.extend(rays.iter().map(|(g, d)| Ray::new(vox.point(*g), Vec3::from(d.map(|x| x as f32 / 7.0 + 0.01)))));
        for bvh in [&binned, &spatial] {
            check_slice::<f32x8, Watertight>(bvh, &all, cap)?;
            check_slice::<f32x16, ExactCrossing>(bvh, &all, cap)?;
        }
    }
}

/// An instance of a voxel surface placed on the grid: grid point `g′` of the object goes to
/// `perm(g′)·sign + shift` in the world (a signed axis permutation and a whole-cell shift, exact
/// in f32 either way).
#[derive(Clone, Copy, Debug)]
struct GridPlace {
    perm: [usize; 3],
    sign: [f32; 3],
    shift: [i32; 3],
}

impl GridPlace {
    /// World grid coordinates of object grid point `g`.
    fn world(&self, g: [f32; 3]) -> [f32; 3] {
        core::array::from_fn(|i| self.sign[i] * g[self.perm[i]] + self.shift[i] as f32)
    }

    /// Object grid coordinates of world grid point `w` (the inverse, exactly).
    fn object(&self, w: [f32; 3]) -> [f32; 3] {
        let mut g = [0.0; 3];
        for i in 0..3 {
            g[self.perm[i]] = (w[i] - self.shift[i] as f32) * self.sign[i];
        }
        g
    }

    /// The object-to-world map in space, for voxels `vox` (`vox.point` on both sides).
    fn transform(&self, vox: &Voxels) -> octoray::scene::Transform {
        let o = vox.point([0.0; 3]);
        let axis = |j: usize| {
            let mut g = [0.0; 3];
            g[j] = 1.0;
            Vec3::from(self.world(g)) - Vec3::from(self.world([0.0; 3]))
        };
        let m = octoray::glam::Mat3::from_cols(axis(0), axis(1), axis(2));
        // world = o + s·(M·(object − o)/s + shift) = M·object + (o − M·o + s·shift).
        let t = o - m * o + Vec3::from(self.shift.map(|x| x as f32)) * vox.scale;
        octoray::scene::Transform::placing(octoray::glam::Affine3A::from_mat3_translation(m, t))
            .expect("invertible")
    }
}

fn grid_places() -> impl Strategy<Value = Vec<GridPlace>> {
    let place = (
        prop::sample::select(vec![[0, 1, 2], [1, 0, 2], [2, 0, 1], [0, 2, 1]]),
        prop::array::uniform3(prop::sample::select(vec![1.0f32, -1.0])),
        prop::array::uniform3(-3i32..=3),
    )
        .prop_map(|(perm, sign, shift)| GridPlace { perm, sign, shift });
    prop::collection::vec(place, 1..4)
}

proptest! {
    #![proptest_config(proptest_config(48))]

    #[test]
    fn containment_and_crossing_parity_are_exact_through_instances(
        (vox, split) in voxels(),
        places in grid_places(),
        identity in any::<bool>(),
        points in prop::collection::vec(prop::array::uniform3(-40i32..=40), 40),
        dirs in prop::collection::vec((prop::array::uniform3(-4i32..=4), 1u32..8), 40),
    ) {
        use octoray::kernels::StableSphere;
        use octoray::prim::PackedSphere;
        use octoray::scene::{Scene, Trace};
        let tris = vox.surface(&split);
        let mut scene = Scene::<VertexTriangle, PackedSphere>::new();
        let g = scene.add_triangles(&tris).expect("build");
        if identity {
            scene.add_instance(&[g], octoray::scene::Transform::IDENTITY, !0);
        }
        for p in &places {
            scene.add_instance(&[g], p.transform(&vox), !0);
        }
        scene.commit().expect("commit");
        let s = scene.as_ref();
        let id = GridPlace { perm: [0, 1, 2], sign: [1.0; 3], shift: [0; 3] };
        let all: Vec<GridPlace> = identity.then_some(id).into_iter().chain(places.iter().copied()).collect();
        // Inside an odd number of instances, each judged in its own grid (the crossing rule's
        // perturbation acts in object space).
        let odd = |w: [f32; 3]| all.iter().filter(|p| vox.oracle(p.object(w))).count() % 2 == 1;
        for (q, (d, len)) in points.iter().zip(&dirs) {
            let w = q.map(|x| x as f32 / 4.0);
            let p = vox.point(w);
            prop_assert_eq!(s.contains::<f32x8, StableSphere>(p, !0), odd(w), "{:?} {:?}", w, all);
            let dist = s.closest_point(p, f32::INFINITY, !0).map_or(f32::INFINITY, |h| h.dist);
            let sd = s.signed_distance::<f32x8, StableSphere>(p, !0);
            prop_assert_eq!(sd.to_bits(), if odd(w) { -dist } else { dist }.to_bits());
            let dg = d.map(|x| x as f32 / 4.0);
            if dg == [0.0; 3] {
                continue;
            }
            let end: [f32; 3] = core::array::from_fn(|i| w[i] + *len as f32 * dg[i]);
            let ray = Ray::with_range(p, Vec3::from(dg) * vox.scale, 0.0, *len as f32);
            let n = s.crossings_ray::<f32x8, StableSphere>(&ray, !0);
            prop_assert_eq!(n % 2 == 1, odd(w) != odd(end), "{:?} {:?} {:?}", w, dg, all);
        }
    }
}

/// The hits of `ray` on each primitive alone, in hit order.
fn brute_force<L: octoray::lanes::Lanes, K: Kernel<L>>(prims: &[K::Prim], ray: &Ray) -> Vec<Hit> {
    let mut hits: Vec<Hit> = (0..prims.len())
        .filter_map(|i| {
            let mut out = [None];
            octoray::closest::<L, K>(&[*ray], &prims[i..=i], &mut out);
            out[0].map(|h| Hit {
                prim: i as u32,
                ..h
            })
        })
        .collect();
    hits.sort_by(hit_order);
    hits
}

/// All hits through the tree, a page of `cap` at a time, equal brute force's.
fn check_all_hits<L: octoray::lanes::Lanes, K: Kernel<L>>(
    bvh: &Bvh8<K::Prim>,
    prims: &[K::Prim],
    ray: &Ray,
    cap: usize,
) -> Result<(), TestCaseError>
where
    K::Prim: Primitive + std::fmt::Debug,
{
    let want = brute_force::<L, K>(prims, ray);
    let mut got = Vec::new();
    let mut page = vec![Hit::default(); cap];
    let mut after = None;
    loop {
        let found = all_hits_ray::<L, K>(bvh.as_ref(), ray, after, &mut page);
        prop_assert!(found.stored <= cap);
        got.extend_from_slice(&page[..found.stored]);
        if found.complete {
            break;
        }
        prop_assert_eq!(found.stored, cap, "an incomplete page is full");
        after = Some(page[cap - 1]);
    }
    prop_assert_eq!(got, want, "{:?}", ray);
    Ok(())
}

/// `all_hits` over `rays` with `cap` slots each equals `all_hits_ray` ray by ray.
fn check_slice<L: octoray::lanes::Lanes, K: Kernel<L>>(
    bvh: &Bvh8<K::Prim>,
    rays: &[Ray],
    cap: usize,
) -> Result<(), TestCaseError> {
    let mut out = vec![Hit::default(); cap * rays.len()];
    let mut found = vec![
        AllHits {
            stored: 9,
            complete: false
        };
        rays.len()
    ];
    all_hits::<L, K>(bvh.as_ref(), rays, &mut out, &mut found);
    for (i, r) in rays.iter().enumerate() {
        let mut one = vec![Hit::default(); cap];
        let f = all_hits_ray::<L, K>(bvh.as_ref(), r, None, &mut one);
        prop_assert_eq!(found[i], f, "ray {}", i);
        prop_assert_eq!(&out[i * cap..][..f.stored], &one[..f.stored], "ray {}", i);
    }
    Ok(())
}

#[test]
fn an_open_or_foreign_mesh_is_refused() {
    let vox = Voxels {
        n: 2,
        filled: vec![true, false, false, false, false, false, false, true],
        origin: Vec3::ZERO,
        scale: 1.0,
    };
    let tris = vox.surface(&[0]);
    let bvh = Bvh8::build(&tris);
    assert!(Solid::new(bvh.as_ref(), &tris).is_ok());
    // Two cubes touching at a vertex only: closed, and each inside.
    let solid = Solid::new(bvh.as_ref(), &tris).unwrap();
    assert!(contains::<f32x8>(solid, Vec3::splat(0.5)));
    assert!(contains::<f32x8>(solid, Vec3::splat(1.5)));
    assert!(!contains::<f32x8>(solid, Vec3::new(1.5, 0.5, 0.5)));
    // One face missing: open, and the error names an edge of the hole.
    let open = &tris[..tris.len() - 1];
    let open_bvh = Bvh8::build(open);
    assert!(matches!(
        Solid::new(open_bvh.as_ref(), open),
        Err(SolidError::OpenEdge { .. })
    ));
    // A flipped face: its edges run the same way as its neighbours'.
    let mut flipped = tris.clone();
    let t = flipped[3];
    flipped[3] = VertexTriangle::new(t.v0.into(), t.v2.into(), t.v1.into());
    let fb = Bvh8::build(&flipped);
    assert!(matches!(
        Solid::new(fb.as_ref(), &flipped),
        Err(SolidError::OpenEdge { .. })
    ));
    // Another mesh's tree, and a non-finite vertex.
    assert!(matches!(
        Solid::new(fb.as_ref(), &tris),
        Err(SolidError::NotItsTree { .. })
    ));
    let mut bad = tris.clone();
    bad[0].v0[0] = f32::NAN;
    let bb = Bvh8::build(&bad);
    assert!(matches!(
        Solid::new(bb.as_ref(), &bad),
        Err(SolidError::NonFinite { tri: 0 } | SolidError::NotItsTree { .. })
    ));
}

#[test]
fn non_finite_points_are_outside() {
    let vox = Voxels {
        n: 1,
        filled: vec![true],
        origin: Vec3::ZERO,
        scale: 1.0,
    };
    let tris = vox.surface(&[2]);
    let bvh = Bvh8::build(&tris);
    let solid = Solid::new(bvh.as_ref(), &tris).unwrap();
    for p in [
        Vec3::NAN,
        Vec3::new(0.5, f32::INFINITY, 0.5),
        Vec3::splat(f32::NEG_INFINITY),
    ] {
        assert!(!contains::<f32x8>(solid, p));
        assert_eq!(winding_number::<f32x8>(solid, p), 0);
    }
    assert!(contains::<f32x8>(solid, Vec3::splat(0.5)));
}

/// Long triangles crossing each other (what spatial splits cut into several leaves), and rays
/// through them: each primitive is reported once, as brute force reports it.
#[test]
fn all_hits_report_a_split_primitive_once() {
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
        ((seed >> 33) as f32 / (1u64 << 31) as f32) * 16.0 - 8.0
    };
    let mut p = || Vec3::new(next(), next(), next());
    let tris: Vec<VertexTriangle> = (0..300)
        .map(|_| {
            let a = p();
            VertexTriangle::new(a, p(), a + 0.2 * p())
        })
        .collect();
    let spatial = Bvh8::try_build_options(&tris, BuildOptions::SPATIAL, &Sequential).unwrap();
    let mut ids: Vec<u32> = spatial
        .as_ref()
        .ids()
        .iter()
        .copied()
        .filter(|&i| i != u32::MAX)
        .collect();
    let slots = ids.len();
    ids.sort_unstable();
    ids.dedup();
    assert!(
        slots > ids.len() + 50,
        "the spatial build split few triangles ({slots} slots)"
    );
    let mut hits = 0;
    for _ in 0..200 {
        let ray = Ray::new(p(), p());
        for cap in [3, 64] {
            check_all_hits::<f32x8, Exact>(&spatial, &tris, &ray, cap).unwrap();
            check_all_hits::<f32x8, Watertight>(&spatial, &tris, &ray, cap).unwrap();
        }
        hits += brute_force::<f32x8, Exact>(&tris, &ray).len();
    }
    assert!(hits > 200, "the rays hit little ({hits})");
    // More rays than one walk's chunk, from one corner (packets) and from anywhere.
    let corner = Vec3::splat(-9.0);
    let mut rays: Vec<Ray> = (0..150).map(|_| Ray::new(corner, p() - corner)).collect();
    rays.extend((0..90).map(|_| Ray::new(p(), p())));
    check_slice::<f32x8, Exact>(&spatial, &rays, 4).unwrap();
}
