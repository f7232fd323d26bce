//! The generalized winding number: within its tolerance of the exact sum of solid angles on
//! triangle soups (open, overlapping, spatial-split trees), 1 inside and 0 outside closed voxel
//! solids, ½ on their surface, odd for a flipped mesh, and defined on bad input.
#![cfg(feature = "triangle")]
use super::solid::{grid_points, trees, voxels};
use octoray::bvh::{Bvh8, WindingTree};
use octoray::glam::Vec3;
use octoray::kernels::triangle::solid_angle::solid_angle;
use octoray::prim::VertexTriangle;
use octoray::tree::generalized_winding_number;
use octoray_testkit::cases::proptest_config;
use proptest::prelude::*;

/// The exact sum over the triangles, one by one.
fn brute_force(tris: &[VertexTriangle], p: Vec3) -> f64 {
    let q = p.to_array().map(f64::from);
    let f = |v: [f32; 3]| v.map(f64::from);
    let s: f64 = tris
        .iter()
        .map(|t| solid_angle([f(t.v0), f(t.v1), f(t.v2)], q))
        .sum();
    s / (4.0 * std::f64::consts::PI)
}

/// Rounding of a sum of `n` terms of magnitude at most ½ taken in another order.
fn rounding(n: usize) -> f64 {
    1e-14 * (n as f64 + 1.0)
}

fn soup() -> impl Strategy<Value = Vec<VertexTriangle>> {
    let v = || prop::array::uniform3(-4.0f32..4.0).prop_map(Vec3::from);
    prop::collection::vec((v(), v(), v()), 1..90).prop_map(|ts| {
        ts.into_iter()
            .map(|(a, b, c)| VertexTriangle::new(a, b * 0.3 + a * 0.7, c * 0.3 + a * 0.7))
            .collect()
    })
}

proptest! {
    #![proptest_config(proptest_config(64))]

    #[test]
    fn within_the_tolerance_of_the_exact_sum_on_any_soup(
        tris in soup(),
        points in prop::collection::vec(prop::array::uniform3(-12.0f32..12.0), 24),
    ) {
        for bvh in trees(&tris) {
            let tree = WindingTree::new(bvh.as_ref());
            for &p in &points {
                let p = Vec3::from(p);
                let want = brute_force(&tris, p);
                for tol in [0.0, 1e-4, 1e-2, 0.3] {
                    let got = generalized_winding_number(&tree, p, tol);
                    prop_assert!(
                        (got - want).abs() <= tol + rounding(tris.len()),
                        "{} vs {} at {:?}, tolerance {}", got, want, p, tol
                    );
                }
            }
        }
    }

    #[test]
    fn one_inside_zero_outside_and_a_half_on_voxel_solids(
        (vox, split) in voxels(),
        points in prop::collection::vec(grid_points(5), 48),
    ) {
        let tris = vox.surface(&split);
        for bvh in trees(&tris) {
            let tree = WindingTree::new(bvh.as_ref());
            for g in &points {
                // An eighth of a cell off the grid is never on the surface.
                let off = g.map(|x| x + 0.125);
                let want = f64::from(u8::from(vox.oracle(off)));
                let got = generalized_winding_number(&tree, vox.point(off), 1e-3);
                prop_assert!((got - want).abs() <= 1e-3 + rounding(tris.len()), "{} at {:?}", got, off);
                // On a face, edge or vertex of the surface: between the two sides.
                let on = generalized_winding_number(&tree, vox.point(*g), 0.0);
                prop_assert!((-1e-9..=1.0 + 1e-9).contains(&on), "{} at {:?}", on, g);
            }
        }
    }
}

#[test]
fn a_point_on_a_closed_surface_is_at_a_half_and_a_flipped_mesh_is_negated() {
    // A cube's faces as two triangles each, counter-clockwise from outside.
    let c = |i: u32| Vec3::new((i & 1) as f32, (i >> 1 & 1) as f32, (i >> 2 & 1) as f32);
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let mut tris = vec![];
    for q in quads {
        tris.push(VertexTriangle::new(c(q[0]), c(q[1]), c(q[2])));
        tris.push(VertexTriangle::new(c(q[0]), c(q[2]), c(q[3])));
    }
    let flipped: Vec<VertexTriangle> = tris
        .iter()
        .map(|t| VertexTriangle::new(t.v0.into(), t.v2.into(), t.v1.into()))
        .collect();
    let (bvh, bvh_flipped) = (Bvh8::build(&tris), Bvh8::build(&flipped));
    let (tree, tree_flipped) = (
        WindingTree::new(bvh.as_ref()),
        WindingTree::new(bvh_flipped.as_ref()),
    );
    for (p, want) in [
        (Vec3::splat(0.5), 1.0),
        (Vec3::new(0.5, 0.25, 0.0), 0.5),
        (Vec3::new(0.25, 0.25, 0.25), 1.0),
        (Vec3::new(3.0, -2.0, 0.5), 0.0),
    ] {
        let got = generalized_winding_number(&tree, p, 1e-6);
        assert!((got - want).abs() < 1e-6 + 1e-12, "{got} at {p}");
        let neg = generalized_winding_number(&tree_flipped, p, 1e-6);
        assert!((neg + want).abs() < 1e-6 + 1e-12, "{neg} at {p}, flipped");
    }
}

#[test]
fn bad_input_has_defined_answers() {
    let tris = [VertexTriangle::new(Vec3::ZERO, Vec3::X, Vec3::Y)];
    let bvh = Bvh8::build(&tris);
    let tree = WindingTree::new(bvh.as_ref());
    assert!(generalized_winding_number(&tree, Vec3::NAN, 0.1).is_nan());
    assert!(generalized_winding_number(&tree, Vec3::new(0.0, f32::INFINITY, 0.0), 0.1).is_nan());
    // A NaN or negative tolerance sums every triangle: the exact answer.
    let p = Vec3::new(0.2, 0.2, 1.0);
    let want = brute_force(&tris, p);
    for tol in [f64::NAN, -1.0, 0.0] {
        assert_eq!(generalized_winding_number(&tree, p, tol), want);
    }
    // No triangles, or none with area: 0.
    let empty = Bvh8::<VertexTriangle>::build(&[]);
    assert_eq!(
        generalized_winding_number(&WindingTree::new(empty.as_ref()), p, 0.1),
        0.0
    );
    let flat = [VertexTriangle::new(Vec3::ZERO, Vec3::X, Vec3::X * 2.0)];
    let flat_bvh = Bvh8::build(&flat);
    assert_eq!(
        generalized_winding_number(&WindingTree::new(flat_bvh.as_ref()), p, 0.1),
        0.0
    );
}

#[test]
fn far_clusters_are_summed_by_their_moments_within_the_bound() {
    // A fine open hemisphere-like cap seen from afar: the tolerance is met while most of the
    // mesh is summed as clusters (checked against the exact sum).
    let mut rng = octoray_testkit::Rng(3);
    let mesh = octoray_testkit::mesh::Mesh::icosphere(5, 0.02, 1.0, Vec3::ZERO, &mut rng);
    let tris: Vec<VertexTriangle> = mesh
        .vertex_tris()
        .into_iter()
        .filter(|t| t.v0[2] + t.v1[2] + t.v2[2] > 0.0)
        .collect();
    let bvh = Bvh8::build(&tris);
    let tree = WindingTree::new(bvh.as_ref());
    for p in [
        Vec3::new(0.1, 0.2, 0.3),
        Vec3::new(0.0, 0.0, -0.5),
        Vec3::new(5.0, 3.0, -2.0),
        Vec3::splat(40.0),
    ] {
        let want = brute_force(&tris, p);
        for tol in [1e-6, 1e-3, 0.05] {
            let got = generalized_winding_number(&tree, p, tol);
            assert!(
                (got - want).abs() <= tol + rounding(tris.len()),
                "{got} vs {want} at {p}, {tol}"
            );
        }
    }
}
