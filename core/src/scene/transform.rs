//! Instance transforms: the affine map from world space into an instance's object space, and
//! the bounds that keep the top level's box tests conservative.

use crate::bvh::SLACK;
use crate::prim::{invert3 as inverse, Aabb, Affine64, Ray};
use glam::{Affine3A, Vec3};

/// Unit roundoff of f32, 2⁻²⁴.
const EPS: f64 = 1.0 / 16_777_216.0;

/// Largest condition number `‖A‖∞·‖A⁻¹‖∞` of an instance the top-level tree bounds. A more
/// nearly singular instance is visited by every ray instead (its world box would need a slack
/// that loosens every top-level box test).
pub const MAX_CONDITION: f64 = 1024.0;

/// An affine map from world space into an instance's object space, `object = A·world + b`,
/// stored as rows `[a₀ a₁ a₂ b]`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Transform {
    /// Row `i`: `A[i][0..3]` and `b[i]`.
    pub rows: [[f32; 4]; 3],
}

impl Transform {
    /// The identity: rays are used as they are.
    pub const IDENTITY: Self = Self {
        rows: [
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
        ],
    };

    /// The transform of an instance placed in the world by `object_to_world` (the matrix a
    /// renderer holds): its inverse, formed in f64 and rounded to f32. `None` when
    /// `object_to_world` is not finite or not invertible (its inverse is then not finite).
    pub fn placing(object_to_world: Affine3A) -> Option<Self> {
        let m = object_to_world.matrix3;
        let cols = [m.x_axis, m.y_axis, m.z_axis];
        let a: [[f64; 3]; 3] =
            core::array::from_fn(|i| core::array::from_fn(|j| f64::from(cols[j][i])));
        let t = object_to_world.translation;
        let (inv, _) = inverse(&a)?;
        let tv = [f64::from(t.x), f64::from(t.y), f64::from(t.z)];
        let rows: [[f32; 4]; 3] = core::array::from_fn(|i| {
            let b = -(inv[i][0] * tv[0] + inv[i][1] * tv[1] + inv[i][2] * tv[2]);
            [
                inv[i][0] as f32,
                inv[i][1] as f32,
                inv[i][2] as f32,
                b as f32,
            ]
        });
        let out = Self { rows };
        out.rows
            .iter()
            .flatten()
            .all(|x| x.is_finite())
            .then_some(out)
    }

    /// True for [`Transform::IDENTITY`] (bit for bit: `−0` entries are not the identity).
    #[inline]
    pub fn is_identity(&self) -> bool {
        // Row by row as 128-bit words: three compares.
        let rows: [u128; 3] = bytemuck::cast(self.rows);
        let id: [u128; 3] = bytemuck::cast(Self::IDENTITY.rows);
        rows == id
    }

    /// The ray in object space: each component of `A·o + b` and `A·d` formed in f64 from the
    /// f32 inputs (the products exact, three rounded sums) and rounded once to f32, so it is
    /// within 1 ulp (plus `2⁻⁵⁰` of the terms' magnitudes) of the exact map. `t_min` and `t_max`
    /// are kept: `t` is measured along both rays alike, so hits from different instances compare
    /// by `t`. The identity returns the ray unchanged.
    #[inline]
    pub fn apply(&self, ray: &Ray) -> Ray {
        if self.is_identity() {
            return *ray;
        }
        let r = &self.rows;
        let map = |v: Vec3, w: f64| {
            let v = [f64::from(v.x), f64::from(v.y), f64::from(v.z)];
            let c = |i: usize| {
                let row = r[i].map(f64::from);
                (row[0] * v[0] + row[1] * v[1] + row[2] * v[2] + row[3] * w) as f32
            };
            Vec3::new(c(0), c(1), c(2))
        };
        Ray {
            origin: map(ray.origin, 1.0),
            dir: map(ray.dir, 0.0),
            t_min: ray.t_min,
            t_max: ray.t_max,
        }
    }

    /// The map in f64 (the f32 entries, exactly).
    pub fn to_f64(&self) -> Affine64 {
        let r = self.rows.map(|row| row.map(f64::from));
        Affine64 {
            m: r.map(|row| [row[0], row[1], row[2]]),
            t: r.map(|row| row[3]),
        }
    }

    /// `A⁻¹` in f64, with `‖A‖∞·‖A⁻¹‖∞`; `None` when `A` is singular or not finite.
    fn inverse(&self) -> Option<([[f64; 3]; 3], f64)> {
        let a: [[f64; 3]; 3] =
            core::array::from_fn(|i| core::array::from_fn(|j| f64::from(self.rows[i][j])));
        inverse(&a)
    }

    /// The condition number `‖A‖∞·‖A⁻¹‖∞` (f64), `None` when `A` is singular or not finite.
    pub fn condition(&self) -> Option<f64> {
        self.inverse().map(|(_, c)| c)
    }

    /// The relative origin slack its level's box tests need for this instance when the tree it
    /// places tests its boxes with relative origin slack `inner` ([`SLACK`] for geometries):
    /// `1.05·κ·(inner + 4ε)`, at least [`SLACK`]; `None` when the instance is not bounded
    /// ([`Transform::world_box_within`]).
    pub fn origin_slack_within(&self, inner: f32) -> Option<f32> {
        let (_, cond) = self.inverse()?;
        let s = 1.05 * cond * (f64::from(inner) + 4.0 * EPS);
        (cond <= MAX_CONDITION && inner.is_finite() && (s as f32).is_finite())
            .then(|| (s as f32).next_up().max(SLACK))
    }

    /// The world box of an instance of a tree of geometries whose object box is `obj`:
    /// [`Transform::world_box_within`] at the geometries' slack, [`SLACK`].
    pub fn world_box(&self, obj: &Aabb) -> Option<Aabb> {
        self.world_box_within(obj, SLACK)
    }

    /// The box in its level's space (the world's or a group's) of an instance whose object box
    /// is `obj`, in which the tree it places tests boxes with relative origin slack `inner`
    /// ([`SLACK`] for geometries, a group's own box-test slack, what its instances need): a box that holds
    /// every point `q` whose transformed ray's hit lies in `obj` — `A⁻¹(obj − b)`, grown by what
    /// the ray's rounding into object space can move a hit (the part that grows with the ray's
    /// origin is the level's origin slack, [`Transform::origin_slack_within`]). `None` when the
    /// condition number exceeds [`MAX_CONDITION`], the box is empty, or a bound is not finite:
    /// every ray visits such an instance.
    ///
    /// Derivation: with `o' = A·o + b − δₒ` and `d' = A·d − δ_d` the rounded ray, a hit at `t`
    /// whose object point `p = o' + t·d'` lies in `obj` grown by the inner origin slack
    /// `inner·‖o'‖` has its point `q = o + t·d` with `A·q + b = p + δₒ + t·δ_d`, where
    /// `‖δₒ‖ ≤ ε‖o'‖` and `‖t·δ_d‖ ≤ ε·t‖d'‖ ≤ ε(‖obj‖ + ‖o'‖)` (all ∞-norms, up to `2⁻⁵⁰`
    /// terms). So `q` lies in `A⁻¹(obj − b)` grown by `‖A⁻¹‖((inner + 2ε)‖o'‖ + ε‖obj‖)`, and
    /// `‖o'‖ ≤ ‖A‖‖o‖ + ‖b‖`: a static part `‖A⁻¹‖((inner + 2ε)‖b‖ + ε‖obj‖)` and a part
    /// `κ(inner + 2ε)‖o‖`. Both are doubled in ε and taken 5 % larger for the f64 terms and
    /// roundings; the f64 inverse's own error adds `2⁻⁴⁰·κ·‖A⁻¹‖(‖obj‖ + ‖b‖)`.
    pub fn world_box_within(&self, obj: &Aabb, inner: f32) -> Option<Aabb> {
        let (inv, cond) = self.inverse()?;
        if cond > MAX_CONDITION || !obj.is_finite() || !inner.is_finite() {
            return None;
        }
        let b = [0, 1, 2].map(|i| f64::from(self.rows[i][3]));
        let norm_inv = inv
            .iter()
            .map(|r| r.iter().map(|x| x.abs()).sum::<f64>())
            .fold(0.0, f64::max);
        let norm_b = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let norm_obj = (0..3).fold(0.0f64, |m, k| {
            m.max(f64::from(obj.lo[k]).abs())
                .max(f64::from(obj.hi[k]).abs())
        });
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for corner in 0..8 {
            let c = [0, 1, 2].map(|k| {
                let v = if (corner >> k) & 1 == 0 {
                    obj.lo[k]
                } else {
                    obj.hi[k]
                };
                f64::from(v) - b[k]
            });
            for i in 0..3 {
                let w = inv[i][0] * c[0] + inv[i][1] * c[1] + inv[i][2] * c[2];
                lo[i] = lo[i].min(w);
                hi[i] = hi[i].max(w);
            }
        }
        let slack = f64::from(inner);
        let grow = 1.05 * norm_inv * ((slack + 4.0 * EPS) * norm_b + 2.0 * EPS * norm_obj)
            + cond * norm_inv * (norm_obj + norm_b) / 1_099_511_627_776.0;
        let down = |x: f64| {
            let y = x as f32;
            if f64::from(y) > x {
                y.next_down()
            } else {
                y
            }
        };
        let up = |x: f64| {
            let y = x as f32;
            if f64::from(y) < x {
                y.next_up()
            } else {
                y
            }
        };
        let out = Aabb {
            lo: core::array::from_fn(|k| down(lo[k] - grow)),
            hi: core::array::from_fn(|k| up(hi[k] + grow)),
        };
        out.is_finite().then_some(out)
    }
}
