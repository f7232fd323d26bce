//! The peers, each used the way a Rust renderer would use it: brute-force closest hit over a
//! slice, and a single-test form `(ray, triangle) -> Option<t>` (t in units of the ray's own
//! direction) for the oracle and the crack test.
//!
//! - `glam_mt`: Möller-Trumbore written by hand on `glam::Vec3A`, with the usual early outs.
//! - `uv_mt`: Möller-Trumbore written by hand on `ultraviolet::Vec3x8` (8 rays per packet), the
//!   common do-it-yourself SIMD.
//! - `obvhs`: `obvhs::triangle::Triangle::intersect`.
//! - `bvh`: `bvh::ray::Ray::intersects_triangle` (normalises the direction and culls back
//!   faces: the single-test form orients each triangle towards the ray and rescales t, so it is
//!   measured on what it is designed for).
//! - `parry3d`: `Triangle::cast_local_ray` and `Ball::cast_local_ray`.
//! - `glam_sphere`: the naive sphere quadratic written by hand on `glam::Vec3A`.

use glam::{Vec3, Vec3A};
use octoray::prim::Ray;
use parry3d::query::RayCast;

/// glam scalar Möller-Trumbore (1997 form, two-sided, early outs), on precomputed v0, e1, e2.
#[inline(always)]
pub fn glam_mt(o: Vec3A, d: Vec3A, v0: Vec3A, e1: Vec3A, e2: Vec3A, t_max: f32) -> Option<f32> {
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - v0;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = d.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t > 0.0 && t <= t_max).then_some(t)
}

/// Triangles precomputed for `glam_mt`.
pub fn glam_tris(tris: &[[Vec3; 3]]) -> Vec<[Vec3A; 3]> {
    tris.iter()
        .map(|t| [t[0].into(), (t[1] - t[0]).into(), (t[2] - t[0]).into()])
        .collect()
}

/// Closest hit per ray with `glam_mt`; returns the number of hits.
pub fn glam_closest(rays: &[Ray], tris: &[[Vec3A; 3]]) -> u32 {
    let mut hits = 0;
    for r in rays {
        let (o, d) = (Vec3A::from(r.origin), Vec3A::from(r.dir));
        let mut best = f32::INFINITY;
        for t in tris {
            if let Some(h) = glam_mt(o, d, t[0], t[1], t[2], best) {
                best = h;
            }
        }
        hits += u32::from(best < f32::INFINITY);
    }
    hits
}

/// ultraviolet `Vec3x8` Möller-Trumbore for 8 rays against one triangle: t (or +inf) per lane.
#[inline(always)]
pub fn uv_mt(
    o: ultraviolet::Vec3x8,
    d: ultraviolet::Vec3x8,
    v0: ultraviolet::Vec3,
    e1: ultraviolet::Vec3,
    e2: ultraviolet::Vec3,
    t_max: ultraviolet::f32x8,
) -> ultraviolet::f32x8 {
    use ultraviolet::{f32x8, Vec3x8};
    use wide07::{CmpGe, CmpGt, CmpLe};
    let (v0, e1, e2) = (Vec3x8::splat(v0), Vec3x8::splat(e1), Vec3x8::splat(e2));
    let p = d.cross(e2);
    let det = e1.dot(p);
    let inv = f32x8::ONE / det;
    let s = o - v0;
    let u = s.dot(p) * inv;
    let q = s.cross(e1);
    let v = d.dot(q) * inv;
    let t = e2.dot(q) * inv;
    let zero = f32x8::ZERO;
    let ok = det.abs().cmp_gt(f32x8::splat(1e-12))
        & u.cmp_ge(zero)
        & v.cmp_ge(zero)
        & (u + v).cmp_le(f32x8::ONE)
        & t.cmp_gt(zero)
        & t.cmp_le(t_max);
    ok.blend(t, f32x8::splat(f32::INFINITY))
}

/// Rays as ultraviolet packets of 8 (the last padded with copies of the final ray).
pub fn uv_packets(rays: &[Ray]) -> Vec<(ultraviolet::Vec3x8, ultraviolet::Vec3x8)> {
    use ultraviolet::{f32x8, Vec3x8};
    rays.chunks(8)
        .map(|c| {
            let get = |i: usize| c[i.min(c.len() - 1)];
            let lane = |f: &dyn Fn(&Ray) -> f32| {
                f32x8::from(core::array::from_fn::<f32, 8, _>(|i| f(&get(i))))
            };
            (
                Vec3x8::new(
                    lane(&|r| r.origin.x),
                    lane(&|r| r.origin.y),
                    lane(&|r| r.origin.z),
                ),
                Vec3x8::new(lane(&|r| r.dir.x), lane(&|r| r.dir.y), lane(&|r| r.dir.z)),
            )
        })
        .collect()
}

/// Triangles precomputed for `uv_mt`.
pub fn uv_tris(tris: &[[Vec3; 3]]) -> Vec<[ultraviolet::Vec3; 3]> {
    let c = |v: Vec3| ultraviolet::Vec3::new(v.x, v.y, v.z);
    tris.iter()
        .map(|t| [c(t[0]), c(t[1] - t[0]), c(t[2] - t[0])])
        .collect()
}

/// Closest hit per packet with `uv_mt`; returns the number of lanes that hit (padding included).
pub fn uv_closest(
    packets: &[(ultraviolet::Vec3x8, ultraviolet::Vec3x8)],
    tris: &[[ultraviolet::Vec3; 3]],
) -> u32 {
    use ultraviolet::f32x8;
    use wide07::CmpLt;
    let mut hits = 0;
    for &(o, d) in packets {
        let mut best = f32x8::splat(f32::INFINITY);
        for t in tris {
            let h = uv_mt(o, d, t[0], t[1], t[2], best);
            best = best.min(h);
        }
        hits += best
            .cmp_lt(f32x8::splat(f32::INFINITY))
            .move_mask()
            .count_ones();
    }
    hits
}

/// obvhs triangles.
pub fn obvhs_tris(tris: &[[Vec3; 3]]) -> Vec<obvhs::triangle::Triangle> {
    tris.iter()
        .map(|t| obvhs::triangle::Triangle {
            v0: t[0].into(),
            v1: t[1].into(),
            v2: t[2].into(),
        })
        .collect()
}

/// Closest hit per ray with obvhs.
pub fn obvhs_closest(rays: &[Ray], tris: &[obvhs::triangle::Triangle]) -> u32 {
    let mut hits = 0;
    for r in rays {
        let mut ray = obvhs::ray::Ray::new_inf(r.origin.into(), r.dir.into());
        for t in tris {
            let h = t.intersect(&ray);
            if h < ray.tmax {
                ray.tmax = h;
            }
        }
        hits += u32::from(ray.tmax < f32::INFINITY);
    }
    hits
}

/// `v` as the `bvh` crate's point.
pub fn bvh_point(v: Vec3) -> nalgebra::Point3<f32> {
    nalgebra::Point3::new(v.x, v.y, v.z)
}

/// bvh triangles (nalgebra points).
pub fn bvh_tris(tris: &[[Vec3; 3]]) -> Vec<[nalgebra::Point3<f32>; 3]> {
    tris.iter().map(|t| t.map(bvh_point)).collect()
}

/// Closest hit per ray with bvh (back faces culled, as the crate does).
pub fn bvh_closest(rays: &[Ray], tris: &[[nalgebra::Point3<f32>; 3]]) -> u32 {
    let mut hits = 0;
    for r in rays {
        let ray = bvh::ray::Ray::new(
            bvh_point(r.origin),
            nalgebra::Vector3::new(r.dir.x, r.dir.y, r.dir.z),
        );
        let mut best = f32::INFINITY;
        for t in tris {
            let h = ray.intersects_triangle(&t[0], &t[1], &t[2]);
            if h.distance < best {
                best = h.distance;
            }
        }
        hits += u32::from(best < f32::INFINITY);
    }
    hits
}

/// parry3d triangles.
pub fn parry_tris(tris: &[[Vec3; 3]]) -> Vec<parry3d::shape::Triangle> {
    let p = |v: Vec3| parry3d::math::Vector::new(v.x, v.y, v.z);
    tris.iter()
        .map(|t| parry3d::shape::Triangle::new(p(t[0]), p(t[1]), p(t[2])))
        .collect()
}

fn parry_ray(r: &Ray) -> parry3d::query::Ray {
    let p = |v: Vec3| parry3d::math::Vector::new(v.x, v.y, v.z);
    parry3d::query::Ray::new(p(r.origin), p(r.dir))
}

/// Closest hit per ray with parry3d.
pub fn parry_closest(rays: &[Ray], tris: &[parry3d::shape::Triangle]) -> u32 {
    let mut hits = 0;
    for r in rays {
        let ray = parry_ray(r);
        let mut best = f32::INFINITY;
        for t in tris {
            if let Some(h) = t.cast_local_ray(&ray, best, true) {
                best = h;
            }
        }
        hits += u32::from(best < f32::INFINITY);
    }
    hits
}

/// Closest sphere per ray with parry3d's `Ball` (the ray moved into the ball's frame).
pub fn parry_spheres(rays: &[Ray], spheres: &[(Vec3, f32)]) -> u32 {
    let mut hits = 0;
    for r in rays {
        let mut best = f32::INFINITY;
        for &(c, rad) in spheres {
            let local = Ray::new(r.origin - c, r.dir);
            if let Some(h) =
                parry3d::shape::Ball::new(rad).cast_local_ray(&parry_ray(&local), best, true)
            {
                best = h;
            }
        }
        hits += u32::from(best < f32::INFINITY);
    }
    hits
}

/// Naive sphere quadratic by hand on glam (nearest positive root).
#[inline(always)]
pub fn glam_sphere(o: Vec3A, d: Vec3A, c: Vec3A, r2: f32, t_max: f32) -> Option<f32> {
    let f = o - c;
    let a = d.dot(d);
    let b = 2.0 * f.dot(d);
    let cc = f.dot(f) - r2;
    let disc = b * b - 4.0 * a * cc;
    if disc < 0.0 {
        return None;
    }
    let sq = disc.sqrt();
    let t0 = (-b - sq) / (2.0 * a);
    let t1 = (-b + sq) / (2.0 * a);
    let t = if t0 > 0.0 { t0 } else { t1 };
    (t > 0.0 && t <= t_max).then_some(t)
}

/// Closest sphere per ray with `glam_sphere`.
pub fn glam_spheres(rays: &[Ray], spheres: &[(Vec3, f32)]) -> u32 {
    let mut hits = 0;
    for r in rays {
        let (o, d) = (Vec3A::from(r.origin), Vec3A::from(r.dir));
        let mut best = f32::INFINITY;
        for &(c, rad) in spheres {
            if let Some(h) = glam_sphere(o, d, c.into(), rad * rad, best) {
                best = h;
            }
        }
        hits += u32::from(best < f32::INFINITY);
    }
    hits
}

/// A peer's single ray-triangle test, t in units of the ray's own direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrianglePeer {
    /// Möller–Trumbore by hand on `glam::Vec3A`.
    Glam,
    /// Möller–Trumbore by hand on `ultraviolet::Vec3x8`.
    Ultraviolet,
    /// `obvhs::triangle::Triangle::intersect`.
    Obvhs,
    /// `bvh::ray::Ray::intersects_triangle`.
    Bvh,
    /// parry3d's `Triangle::cast_local_ray`.
    Parry,
}

impl TrianglePeer {
    /// Every peer, in the order the reports list them.
    pub const ALL: [TrianglePeer; 5] = [
        Self::Glam,
        Self::Ultraviolet,
        Self::Obvhs,
        Self::Bvh,
        Self::Parry,
    ];
    /// The reports' name for the peer.
    pub fn name(self) -> &'static str {
        match self {
            Self::Glam => "glam MT (hand-written, scalar)",
            Self::Ultraviolet => "ultraviolet Vec3x8 MT (hand-written)",
            Self::Obvhs => "obvhs 0.4 Triangle::intersect",
            Self::Bvh => "bvh 0.13 intersects_triangle",
            Self::Parry => "parry3d 0.31 Triangle ray cast",
        }
    }

    /// One ray against one triangle.
    pub fn test(self, ray: &Ray, tri: [Vec3; 3]) -> Option<f32> {
        let in_range = |t: f32| (t.is_finite() && t >= ray.t_min && t <= ray.t_max).then_some(t);
        match self {
            Self::Glam => {
                let g = glam_tris(&[tri])[0];
                glam_mt(
                    ray.origin.into(),
                    ray.dir.into(),
                    g[0],
                    g[1],
                    g[2],
                    ray.t_max,
                )
                .and_then(in_range)
            }
            Self::Ultraviolet => {
                let p = uv_packets(&[*ray])[0];
                let t = uv_tris(&[tri])[0];
                let h = uv_mt(
                    p.0,
                    p.1,
                    t[0],
                    t[1],
                    t[2],
                    ultraviolet::f32x8::splat(ray.t_max),
                );
                in_range(h.as_array_ref()[0])
            }
            Self::Obvhs => {
                let r =
                    obvhs::ray::Ray::new(ray.origin.into(), ray.dir.into(), ray.t_min, ray.t_max);
                in_range(obvhs_tris(&[tri])[0].intersect(&r))
            }
            Self::Bvh => {
                // Orient the triangle towards the ray (bvh culls back faces) and rescale t from
                // bvh's normalised direction to units of ours.
                let n = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
                let tri = if n.dot(ray.dir) > 0.0 {
                    [tri[0], tri[2], tri[1]]
                } else {
                    tri
                };
                let len = ray.dir.length();
                let r = bvh::ray::Ray::new(
                    bvh_point(ray.origin),
                    nalgebra::Vector3::new(ray.dir.x, ray.dir.y, ray.dir.z),
                );
                let [a, b, c] = tri.map(bvh_point);
                let h = r.intersects_triangle(&a, &b, &c);
                in_range(h.distance / len)
            }
            Self::Parry => {
                let t = parry_tris(&[tri])[0];
                t.cast_local_ray(&parry_ray(ray), ray.t_max, true)
                    .and_then(in_range)
            }
        }
    }
}
