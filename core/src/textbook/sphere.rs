//! The textbook ray-sphere test, line by line (its accuracy: the [module docs](super)).

use super::TextbookHit;
use crate::prim::{Ray, Sphere};
use glam::Vec3;

/// Why the textbook sphere test ended where it did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SphereOutcome {
    /// The nearest root in `[t_min, t_max]`; `inside` when the origin is inside the sphere
    /// (the roots straddle zero, so the far root is the hit).
    Hit {
        /// The hit.
        hit: TextbookHit,
        /// The near root is negative and the far one positive: the origin is inside.
        inside: bool,
    },
    /// Radius not finite and `> 0`, direction zero, or a non-finite input.
    Invalid,
    /// The discriminant is negative: the line misses the sphere.
    NoRealRoot,
    /// Both roots lie outside `[t_min, t_max]` (for example behind the ray).
    OutOfRange,
}

/// Every intermediate value of the textbook ray-sphere test, as on the sheet.
/// Fields the test did not reach are NaN.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereSteps {
    /// `f = o − c`.
    pub f: Vec3,
    /// `A = d·d`.
    pub a: f32,
    /// `B = 2 (f·d)`.
    pub b: f32,
    /// `C = f·f − r²`.
    pub c: f32,
    /// `B² − 4AC`.
    pub disc: f32,
    /// `(−B − √disc) / 2A`, the near root.
    pub t_near: f32,
    /// `(−B + √disc) / 2A`, the far root.
    pub t_far: f32,
    /// The outcome.
    pub outcome: SphereOutcome,
}

/// Runs the textbook sphere test and returns all its intermediate values.
pub fn sphere_steps(ray: &Ray, sphere: &Sphere) -> SphereSteps {
    let (o, d, r) = (ray.origin, ray.dir, sphere.radius);
    let mut s = SphereSteps {
        f: o - sphere.center,
        a: f32::NAN,
        b: f32::NAN,
        c: f32::NAN,
        disc: f32::NAN,
        t_near: f32::NAN,
        t_far: f32::NAN,
        outcome: SphereOutcome::Invalid,
    };
    // |o + t·d − c|² = r² expands to (d·d) t² + 2 (f·d) t + (f·f − r²) = 0.
    s.a = d.dot(d);
    s.b = 2.0 * s.f.dot(d);
    s.c = s.f.dot(s.f) - r * r;
    s.disc = s.b * s.b - 4.0 * s.a * s.c;
    let finite = s.a.is_finite() && s.b.is_finite() && s.c.is_finite() && s.disc.is_finite();
    if !(r > 0.0 && s.a > 0.0 && finite) {
        return s;
    }
    if s.disc < 0.0 {
        s.outcome = SphereOutcome::NoRealRoot;
        return s;
    }
    let sq = libm::sqrtf(s.disc);
    s.t_near = (-s.b - sq) / (2.0 * s.a);
    s.t_far = (-s.b + sq) / (2.0 * s.a);
    let in_range = |t: f32| t.is_finite() && t >= ray.t_min && t <= ray.t_max;
    let t = if in_range(s.t_near) {
        s.t_near
    } else if in_range(s.t_far) {
        s.t_far
    } else {
        s.outcome = SphereOutcome::OutOfRange;
        return s;
    };
    let point = ray.at(t);
    s.outcome = if point.is_finite() {
        SphereOutcome::Hit {
            hit: TextbookHit { t, point },
            inside: s.t_near < 0.0 && s.t_far > 0.0,
        }
    } else {
        SphereOutcome::OutOfRange
    };
    s
}

/// The textbook sphere test's answer: the nearest hit in range, or `None`.
pub fn intersect_sphere(ray: &Ray, sphere: &Sphere) -> Option<TextbookHit> {
    match sphere_steps(ray, sphere).outcome {
        SphereOutcome::Hit { hit, .. } => Some(hit),
        _ => None,
    }
}
