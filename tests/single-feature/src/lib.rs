//! What a single-primitive build (`--no-default-features --features triangle` or `sphere`) must
//! still do: the seed problems of its primitive through the textbook core, the scalar twin and
//! the 8-lane packet. `.ci/run` runs it on both builds, with nothing else enabling the other
//! feature.
#![cfg(test)]

#[cfg(feature = "triangle")]
mod triangles {
    use octoray::glam::Vec3;
    use octoray::kernels::MollerTrumbore;
    use octoray::prim::{PackedTriangle, Ray, VertexTriangle};
    use octoray::textbook::{self, InsideTest};
    use octoray::{closest, f32x8};

    #[test]
    fn seed_triangle_1_hits_at_t_2_everywhere() {
        let ray = Ray::new(Vec3::new(-4.0, -2.0, -1.0), Vec3::new(1.0, 2.0, 3.0));
        let tri = VertexTriangle::new(
            Vec3::new(0.0, 6.0, 7.0),
            Vec3::new(-3.0, 1.0, 5.0),
            Vec3::new(-2.0, 1.0, 4.0),
        );
        assert_eq!(
            textbook::intersect_triangle(&ray, &tri, InsideTest::Full).map(|h| h.t),
            Some(2.0)
        );
        let packed = PackedTriangle::from(tri);
        assert_eq!(
            octoray::intersect_triangle(&ray, &packed).map(|h| h.t),
            Some(2.0)
        );
        let mut hits = [None; 3];
        closest::<f32x8, MollerTrumbore>(&[ray; 3], &[packed], &mut hits);
        assert!(hits.iter().all(|h| h.map(|h| h.t) == Some(2.0)));
    }
}

#[cfg(feature = "sphere")]
mod spheres {
    use octoray::glam::Vec3;
    use octoray::kernels::StableSphere;
    use octoray::prim::{PackedSphere, Ray, Sphere};
    use octoray::{closest, f32x8, textbook};

    #[test]
    fn seed_spheres_hit_and_miss_everywhere() {
        let ray = Ray::new(Vec3::new(-4.0, -2.0, -1.0), Vec3::new(1.0, 2.0, 3.0));
        let spheres = [
            (Sphere::new(Vec3::ZERO, 10.0), true),
            (Sphere::new(Vec3::new(-3.0, 0.0, 2.0), 1.0), true),
            (Sphere::new(Vec3::new(-5.0, -6.0, -7.0), 2.0), false),
            (Sphere::new(Vec3::new(0.0, 0.0, -1.0), 3.0), false),
        ];
        for (s, hit) in spheres {
            assert_eq!(textbook::intersect_sphere(&ray, &s).is_some(), hit);
            let packed = PackedSphere::from(s);
            let twin = octoray::intersect_sphere(&ray, &packed);
            assert_eq!(twin.is_some(), hit);
            let mut out = [None; 2];
            closest::<f32x8, StableSphere>(&[ray; 2], &[packed], &mut out);
            assert!(out.iter().all(|h| *h == twin));
        }
    }
}
