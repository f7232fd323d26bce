//! Prints the seven textbook problems of `shared/seed/problems.md` solved step by step, like the
//! worked sheet, using the textbook core's `*_steps` API, and checks each answer against the
//! packet kernels.
//!
//! Run: `cargo run --example textbook`

use octoray::glam::Vec3;
use octoray::prim::{PackedSphere, PackedTriangle, Ray, Sphere, VertexTriangle};
use octoray::textbook::{self, InsideTest, SphereOutcome, TriangleOutcome};

fn fmt(v: Vec3) -> String {
    format!("({}, {}, {})", v.x, v.y, v.z)
}

fn main() {
    let ray = Ray::new(Vec3::new(-4.0, -2.0, -1.0), Vec3::new(1.0, 2.0, 3.0));
    let v = Vec3::new;
    let triangles = [
        VertexTriangle::new(v(0.0, 6.0, 7.0), v(-3.0, 1.0, 5.0), v(-2.0, 1.0, 4.0)),
        VertexTriangle::new(v(-2.0, 1.0, 2.0), v(-1.0, 1.0, 1.0), v(1.0, 6.0, 4.0)),
        VertexTriangle::new(v(0.0, 0.0, 0.0), v(2.0, 4.0, 6.0), v(1.0, 0.0, 0.0)),
    ];
    let spheres = [
        Sphere::new(v(0.0, 0.0, 0.0), 10.0),
        Sphere::new(v(-3.0, 0.0, 2.0), 1.0),
        Sphere::new(v(-5.0, -6.0, -7.0), 2.0),
        Sphere::new(v(0.0, 0.0, -1.0), 3.0),
    ];
    println!(
        "Ray: o = {}, d = {} (t in units of d)\n",
        fmt(ray.origin),
        fmt(ray.dir)
    );

    for (i, tri) in triangles.iter().enumerate() {
        let s = textbook::triangle_steps(&ray, tri, InsideTest::Full);
        let [a1, a2, a3] = tri.vertices();
        println!(
            "Ray-triangle problem {}: a1 = {}, a2 = {}, a3 = {}",
            i + 1,
            fmt(a1),
            fmt(a2),
            fmt(a3)
        );
        println!("  a1a2 = {}, a1a3 = {}", fmt(a2 - a1), fmt(a3 - a1));
        println!("  n = a1a2 x a1a3 = {}", fmt(s.n));
        println!("  a1o = {}", fmt(ray.origin - a1));
        println!("  d . n = {}, (o - a1) . n = {}", s.d_dot_n, s.o_dot_n);
        match s.outcome {
            TriangleOutcome::Parallel => {
                println!("  d . n = 0: the ray is parallel to the plane ((o - a1) . n = {} != 0, so not in it).", s.o_dot_n);
                println!("  => no intersection\n");
                continue;
            }
            TriangleOutcome::Degenerate => {
                println!("  n = 0: degenerate triangle => no intersection\n");
                continue;
            }
            _ => {}
        }
        println!("  t = -((o - a1) . n) / (d . n) = {}", s.t);
        println!("  p = o + t d = {}", fmt(s.p));
        for (k, pv) in s.to_vertices.iter().enumerate() {
            println!("  pa{0} = a{0} - p = {1}", k + 1, fmt(*pv));
        }
        let axis = ["x", "y", "z"][s.dominant_axis];
        for (k, (edge, c)) in ["(pa1 x pa2)", "(pa2 x pa3)", "(pa3 x pa1)"]
            .iter()
            .zip(s.edge_cross)
            .enumerate()
        {
            println!(
                "  {edge} = {}: {axis} component {}, along n {}",
                fmt(c),
                s.edge_tests_dominant[k],
                s.edge_tests[k]
            );
        }
        let short = textbook::intersect_triangle(&ray, tri, InsideTest::DominantAxis);
        let kernel = octoray::intersect_triangle(&ray, &PackedTriangle::from(*tri));
        match s.outcome {
            TriangleOutcome::Hit(h) => println!(
                "  all agree in sign: inside => hit at {} (t = {})",
                fmt(h.point),
                h.t
            ),
            _ => println!("  mixed signs: outside => no intersection"),
        }
        println!(
            "  dominant-axis shortcut agrees: {}; packet kernel (Moller-Trumbore) agrees: {}\n",
            short.is_some() == matches!(s.outcome, TriangleOutcome::Hit(_)),
            kernel.map(|h| h.t) == short.map(|h| h.t)
        );
    }

    for (i, sph) in spheres.iter().enumerate() {
        let s = textbook::sphere_steps(&ray, sph);
        println!(
            "Ray-sphere problem {}: c = {}, r = {}",
            i + 1,
            fmt(sph.center),
            sph.radius
        );
        println!("  f = o - c = {}", fmt(s.f));
        println!(
            "  A = d . d = {}, B = 2 (f . d) = {}, C = f . f - r^2 = {}",
            s.a, s.b, s.c
        );
        println!("  disc = B^2 - 4AC = {}", s.disc);
        if s.disc >= 0.0 {
            println!("  t = (-B -/+ sqrt disc) / 2A = {} , {}", s.t_near, s.t_far);
        }
        match s.outcome {
            SphereOutcome::Hit { hit, inside } => {
                if inside {
                    println!(
                        "  roots of opposite sign: the origin is inside; the far root is the hit"
                    );
                } else {
                    println!("  both roots positive: the nearer is the hit");
                }
                println!("  => hit at {} (t = {})", fmt(hit.point), hit.t);
            }
            SphereOutcome::NoRealRoot => println!("  disc < 0 => no intersection"),
            SphereOutcome::OutOfRange => {
                println!("  both roots negative (behind the ray) => no intersection")
            }
            SphereOutcome::Invalid => println!("  invalid input => no intersection"),
        }
        let kernel = octoray::intersect_sphere(&ray, &PackedSphere::from(*sph));
        println!("  stable packet kernel: {:?}\n", kernel.map(|h| h.t));
    }
}
