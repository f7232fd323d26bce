//! Nested instancing: a plant of three tetrahedra (a group), a row of 100 plants (a group of
//! groups), a field of 100 rows placed in the world: 120 000 virtual triangles from four stored
//! triangles and 203 instances. A hit names its instance path, read back as instances.
use octoray::f32x8;
use octoray::glam::{Affine3A, Quat, Vec3};
use octoray::kernels::{StableSphere, Watertight};
use octoray::prim::{PackedSphere, Ray, RayLanes, VertexTriangle};
use octoray::scene::{Scene, Tracer, Transform};

fn main() {
    let p = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z].map(|v| v - Vec3::splat(0.25));
    let tet: Vec<VertexTriangle> = [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]]
        .iter()
        .map(|&[a, b, c]| VertexTriangle::new(p[a], p[b], p[c]))
        .collect();
    let place = |scale: f32, turn: f32, at: Vec3| {
        let m = Affine3A::from_scale_rotation_translation(
            Vec3::splat(scale),
            Quat::from_rotation_y(turn),
            at,
        );
        Transform::placing(m).expect("invertible")
    };
    let mut scene = Scene::<VertexTriangle, PackedSphere>::new();
    let mesh = scene.add_triangles(&tet).expect("build");
    // A group is filled first, then placed: a plant of three stacked tetrahedra...
    let plant = scene.add_group();
    for k in 0..3 {
        let size = 1.0 - 0.25 * k as f32;
        scene.add_to_group(
            plant,
            &[mesh],
            place(size, k as f32, Vec3::Y * k as f32 * 0.6),
            !0,
        );
    }
    // ...a row of 100 plants (a group holds groups made before it)...
    let row = scene.add_group();
    for i in 0..100 {
        let at = Vec3::new(i as f32 * 2.0, 0.0, 0.0);
        scene.place_group(Some(row), plant, place(0.8, i as f32 * 0.7, at), !0);
    }
    // ...and 100 rows in the world; the rows past the 50th have mask 2.
    for j in 0..100 {
        let mask = if j < 50 { 1 | 2 } else { 2 };
        let at = Vec3::new(0.0, 0.0, j as f32 * 2.0);
        scene.place_group(None, row, place(1.0, 0.0, at), mask);
    }
    scene.commit().expect("commit");
    let s = scene.as_ref();
    let tracer = Tracer::<f32x8, Watertight, StableSphere>::new(s);
    println!(
        "{} stored triangles, {} instances, {} instance paths: {} virtual triangles",
        tet.len(),
        s.instances().len(),
        s.paths(),
        s.paths() * tet.len() as u64
    );

    // Straight down onto row 70, plant 30: the hit's path is (row, plant, tetrahedron).
    let down = Ray::new(Vec3::new(60.0, 10.0, 140.0), -Vec3::Y);
    for mask in [!0, 1] {
        match tracer.closest_ray(&down, mask) {
            Some(h) => {
                let path = s.instance_path(h.inst).expect("a reported path");
                println!(
                    "mask {mask:#x}: t = {:.4}, path {} = instances {:?}",
                    h.t,
                    h.inst,
                    path.as_slice()
                );
            }
            None => println!("mask {mask:#x}: no hit (row 70 has mask 2)"),
        }
    }

    // A packet along the rows: lanes in eight rows, each its own path.
    let rays: Vec<Ray> = (0..8)
        .map(|i| Ray::new(Vec3::new(-5.0, 0.2, i as f32 * 2.0), Vec3::X))
        .collect();
    let hits = tracer.closest_packet(&RayLanes::load(&rays), !0);
    for i in 0..rays.len() {
        if let Some(h) = hits.lane(i) {
            let path = s.instance_path(h.inst).expect("a reported path");
            println!("lane {i}: t = {:.3}, instances {:?}", h.t, path.as_slice());
        }
    }
}
