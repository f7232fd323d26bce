//! A two-level scene: a mesh and a set of spheres as geometries, a field of 400 instances of the
//! mesh (rotated, scaled, one mirrored), the spheres placed once, a ground of two meshes in one
//! tree; one ray, a packet, and masks.
use octoray::f32x8;
use octoray::glam::{Affine3A, Quat, Vec3};
use octoray::kernels::{StableSphere, Watertight};
use octoray::prim::{PackedSphere, Ray, RayLanes, VertexTriangle};
use octoray::scene::{Scene, Tracer, Transform};

fn main() {
    // A unit tetrahedron, and two ground quads as two more meshes.
    let p = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z].map(|v| v - Vec3::splat(0.25));
    let tet: Vec<VertexTriangle> = [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]]
        .iter()
        .map(|&[a, b, c]| VertexTriangle::new(p[a], p[b], p[c]))
        .collect();
    let quad = |x0: f32, x1: f32| {
        let (a, b) = (Vec3::new(x0, -1.0, -50.0), Vec3::new(x1, -1.0, -50.0));
        let (c, d) = (Vec3::new(x1, -1.0, 50.0), Vec3::new(x0, -1.0, 50.0));
        vec![VertexTriangle::new(a, b, c), VertexTriangle::new(a, c, d)]
    };
    let mut scene = Scene::<VertexTriangle, PackedSphere>::new();
    let mesh = scene.add_triangles(&tet).expect("build");
    let balls = scene.add_spheres(&[PackedSphere::new(Vec3::new(0.0, 3.0, 0.0), 1.0)]);
    let balls = balls.expect("build");
    let west = scene.add_triangles(&quad(-50.0, 0.0)).expect("build");
    let east = scene.add_triangles(&quad(0.0, 50.0)).expect("build");
    // Static meshes share one tree: one instance of the set.
    scene.add_instance(&[west, east], Transform::IDENTITY, 1);
    scene.add_instance(&[balls], Transform::IDENTITY, 1 | 2);
    for i in 0..400 {
        let (x, z) = ((i % 20) as f32 * 2.0 - 19.0, (i / 20) as f32 * 2.0 - 19.0);
        let scale = if i == 0 {
            Vec3::new(-1.0, 1.0, 1.0)
        } else {
            Vec3::splat(0.8)
        };
        let place = Affine3A::from_scale_rotation_translation(
            scale,
            Quat::from_rotation_y(i as f32 * 0.3),
            Vec3::new(x, 0.0, z),
        );
        let t = Transform::placing(place).expect("invertible");
        scene.add_instance(&[mesh], t, 1);
    }
    scene.commit().expect("commit");
    let s = scene.as_ref();
    let tracer = Tracer::<f32x8, Watertight, StableSphere>::new(s);
    println!(
        "{} geometries, {} trees, {} instances",
        s.geometries().len(),
        s.trees().len(),
        s.instances().len()
    );

    let down = Ray::new(Vec3::new(1.0, 10.0, -19.0), -Vec3::Y);
    let hit = tracer.closest_ray(&down, !0);
    println!("straight down onto an instance: {hit:?}");
    // Mask 2 sees only the spheres' instance.
    let up = Ray::new(Vec3::new(0.0, -5.0, 0.0), Vec3::Y);
    for mask in [!0, 2] {
        let h = tracer.closest_ray(&up, mask);
        println!("up from below, mask {mask:#x}: {h:?}");
    }

    // A packet across the field.
    let rays: Vec<Ray> = (0..8)
        .map(|i| Ray::new(Vec3::new(-25.0, 0.0, i as f32 * 2.0 - 7.0), Vec3::X))
        .collect();
    let hits = tracer.closest_packet(&RayLanes::load(&rays), !0);
    for i in 0..rays.len() {
        if let Some(h) = hits.lane(i) {
            println!(
                "lane {i}: t = {:.3}, geometry {}, instance {}",
                h.t, h.geom, h.inst
            );
        }
    }
}
