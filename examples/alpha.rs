//! Alpha testing through a hit filter: a leafy quad whose cut-out texels let rays through,
//! for closest hits and shadow rays, against the restart loop a renderer writes without one.
use octoray::bvh::Bvh8;
use octoray::f32x8;
use octoray::glam::Vec3;
use octoray::hit::Candidate;
use octoray::kernels::Watertight;
use octoray::prim::{Ray, VertexTriangle};
use octoray::tree::{closest_ray, closest_ray_with, occluded_ray_with};

/// The leaves' alpha texture: a 4×4 grid over the barycentrics, opaque on every third
/// square, shifted by a square from one leaf to the next (a leaf is two triangles); the wall
/// (triangles 20 and 21) is opaque everywhere.
fn opaque(c: &Candidate) -> bool {
    let square = (c.u * 4.0) as u32 + (c.v * 4.0) as u32 + c.prim / 2;
    c.prim >= 20 || square.is_multiple_of(3)
}

fn main() {
    // A stack of ten leaf quads at z = 1..10, and a wall behind them at z = 20.
    let mut tris = Vec::new();
    for z in (1..=10).map(|k| k as f32).chain([20.0]) {
        let (a, b) = (Vec3::new(-1.0, -1.0, z), Vec3::new(1.0, -1.0, z));
        let (c, d) = (Vec3::new(1.0, 1.0, z), Vec3::new(-1.0, 1.0, z));
        tris.push(VertexTriangle::new(a, b, c));
        tris.push(VertexTriangle::new(a, c, d));
    }
    let bvh = Bvh8::build(&tris);
    let b = bvh.as_ref();
    let mut through = [0usize; 3];
    let mut restarts = 0;
    for i in 0..1000 {
        let (x, y) = (
            (i % 40) as f32 / 20.0 - 0.975,
            (i / 40) as f32 / 12.5 - 0.96,
        );
        let ray = Ray::new(Vec3::new(x, y, 0.0), Vec3::Z);
        // The filter: cut-out hits neither count nor shorten the ray.
        let mut filter = |c: &Candidate| opaque(c);
        let h = closest_ray_with::<f32x8, Watertight, _>(b, &ray, &mut filter).expect("the wall");
        // The restart loop: trace, and on a cut-out hit trace again from just past it.
        let mut r = ray;
        let again = loop {
            let h = closest_ray::<f32x8, Watertight>(b, &r).expect("the wall");
            if opaque(&Candidate::from_hit(&h, 0)) {
                break h;
            }
            restarts += 1;
            r.t_min = h.t.next_up();
        };
        assert_eq!((h.t, h.prim), (again.t, again.prim));
        through[if h.t >= 20.0 {
            2
        } else if h.t > 1.0 {
            1
        } else {
            0
        }] += 1;
        // A shadow ray with the same alpha: blocked only by an opaque texel.
        let shadow = Ray::with_range(ray.origin, ray.dir, 0.0, 15.0);
        let blocked =
            occluded_ray_with::<f32x8, Watertight, _>(b, &shadow, &mut |c: &Candidate| opaque(c));
        assert_eq!(blocked, h.t <= 15.0);
    }
    println!(
        "1000 rays: {} stopped by the first leaf, {} by a later one, {} reached the wall",
        through[0], through[1], through[2]
    );
    println!("the restart loop traced {restarts} extra rays; the filter none");
}
