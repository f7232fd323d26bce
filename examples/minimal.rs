//! Build a scene, trace one ray and one packet, print the hits.
use octoray::bvh::Bvh8;
use octoray::f32x8;
use octoray::glam::Vec3;
use octoray::kernels::Watertight;
use octoray::prim::{Ray, RayLanes, VertexTriangle};
use octoray::tree::{closest_packet, closest_ray};

fn main() {
    // Two triangles forming the unit square in z = 0.
    let (a, b, c, d) = (Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y);
    let tris = [VertexTriangle::new(a, b, c), VertexTriangle::new(a, c, d)];
    let bvh = Bvh8::build(&tris);

    let ray = Ray::new(Vec3::new(0.25, 0.75, 1.0), -Vec3::Z);
    println!(
        "one ray: {:?}",
        closest_ray::<f32x8, Watertight>(bvh.as_ref(), &ray)
    );

    let rays: Vec<Ray> = (0..8)
        .map(|i| Ray::new(Vec3::new(i as f32 * 0.2, 0.5, 1.0), -Vec3::Z))
        .collect();
    let hits = closest_packet::<f32x8, Watertight>(bvh.as_ref(), &RayLanes::load(&rays));
    for (i, r) in rays.iter().enumerate() {
        println!(
            "packet lane {i} from x = {:.1}: {:?}",
            r.origin.x,
            hits.lane(i)
        );
    }
}
