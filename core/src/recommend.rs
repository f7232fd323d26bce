//! Choosing a tier from the scene: the cheapest tier whose documented bounds meet an error
//! budget, with the reasoning as a report.
//!
//! The model, from the tiers' contracts (measured against the exact oracle):
//! - `scale = max|coordinate| + diagonal` of the scene bounds: every f32 rounding is relative to
//!   coordinates of that size (translation costs precision).
//! - Position error of a reported hit: `8·ε·scale` for the f32 tiers (the t bound at normal
//!   incidence; grazing rays multiply it by 1/|cos θ|), `2·2⁻⁵³·scale` for f64.
//! - Hit/miss is exact outside a band of `64·ε·scale` around edges; a feature narrower than four
//!   bands is not reliably hit, so `64·ε·scale ≤ smallest_feature / 4` is required too.
//! - Range: the standard tier's products of three coordinates overflow beyond ~7e12 and underflow
//!   below ~1e-15 (we require `scale ≤ 1e12`, `smallest_feature ≥ 1e-12`); the watertight tier's
//!   origin-relative products of two hold to `scale ≤ 1e18`, `smallest_feature ≥ 1e-18`.
//! - Inputs are f32 for every tier (f64 computes exactly on them): a feature narrower than 16
//!   ulps of the largest coordinate has already lost its shape in the input, and no tier can
//!   recover it (translate the scene towards the origin).
//! - Closed meshes that must not leak (refraction, inside/outside tests) need the watertight tier
//!   whatever the budget: the standard tier lets 1.540 % (report: `standard, 8 lanes`, crack
//!   rate) of the trade report's crack rays through.
//! - An error budget of zero (no error to spend on decisions) gets the exact tier: every hit/miss
//!   and range decision equals the exact answer for the f32 inputs, for every finite input
//!   (watertight by construction); reported positions still carry the f32 bound, so the report
//!   says the budget is not met.

//!
//! ```
//! use octoray_core::glam::Vec3;
//! use octoray_core::recommend::{recommend, SceneSpec, TierChoice};
//!
//! // A room-sized scene near the origin, millimetre features, a 0.1 mm budget.
//! let room = SceneSpec {
//!     bounds_min: Vec3::splat(-5.0),
//!     bounds_max: Vec3::splat(5.0),
//!     smallest_feature: 1e-3,
//!     error_budget: 1e-4,
//!     closed_meshes: false,
//! };
//! assert_eq!(recommend(&room)?.tier, TierChoice::Standard);
//! // The same room (with 5 cm features) 10 km from the origin: f32 cannot hold 0.1 mm there.
//! let far = SceneSpec {
//!     bounds_min: Vec3::splat(1e4),
//!     bounds_max: Vec3::splat(1e4 + 10.0),
//!     smallest_feature: 0.05,
//!     ..room
//! };
//! let r = recommend(&far)?;
//! assert_eq!(r.tier, TierChoice::F64);
//! assert!(r.to_string().starts_with("tier f64: the f32 error bound 4.78e-3 at scale 1.00e4"));
//! // Millimetre features there are already lost in the f32 input: the report says so.
//! let lost = recommend(&SceneSpec { smallest_feature: 1e-3, ..far })?;
//! assert!(!lost.meets_budget && lost.to_string().contains("translate the scene"));
//! // A description that is not a scene is an error, not an answer.
//! let nan = SceneSpec { smallest_feature: f32::NAN, ..room };
//! assert!(recommend(&nan).is_err());
//! # Ok::<(), octoray_core::recommend::SpecError>(())
//! ```

use core::fmt;
use glam::Vec3;

/// What the recommender needs to know about a scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneSpec {
    /// Lower corner of the scene's bounds (camera included).
    pub bounds_min: Vec3,
    /// Upper corner.
    pub bounds_max: Vec3,
    /// The smallest feature that must be hit reliably (edge length, sphere radius).
    pub smallest_feature: f32,
    /// The largest acceptable error of a hit position, in scene units; `0.0`: no error may be
    /// spent on hit/miss decisions (the exact tier).
    pub error_budget: f32,
    /// The scene has closed meshes that must not leak rays.
    pub closed_meshes: bool,
}

/// A tier the recommender can pick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TierChoice {
    /// [`crate::kernels::MollerTrumbore`].
    Standard,
    /// [`crate::kernels::Watertight`].
    Watertight,
    /// The standard kernel at f64 lanes (not watertight: never chosen for closed meshes).
    F64,
    /// The watertight kernel at f64 lanes: closed meshes that need f64.
    WatertightF64,
    /// [`crate::kernels::Exact`]: no error budget to spend (hit/miss decided exactly).
    Exact,
}

impl TierChoice {
    /// Lower-case name, as the demo's `--tier` takes it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Standard => "standard",
            Self::Watertight => "watertight",
            Self::F64 => "f64",
            Self::WatertightF64 => "watertight-f64",
            Self::Exact => "exact",
        }
    }
}

/// The recommender's answer; its `Display` is the report.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Recommendation {
    /// The cheapest tier that meets the budget (or f64, the most accurate, when none does).
    pub tier: TierChoice,
    /// Whether the chosen tier's documented bounds meet the budget.
    pub meets_budget: bool,
    /// The scene scale the bounds were computed from.
    pub scale: f32,
    /// The f32 tiers' position error bound at this scale.
    pub f32_error: f32,
    /// The f64 tier's position error bound at this scale.
    pub f64_error: f32,
    /// The largest coordinate magnitude.
    pub extent: f32,
    /// The smallest feature asked for.
    pub smallest_feature: f32,
    why: Why,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Why {
    StandardFits,
    ClosedMeshes,
    StandardRange,
    F32Error,
    NoneFits,
    InputQuantization,
    NoBudget,
}

const EPS32: f32 = f32::EPSILON / 2.0;
const EPS64: f64 = f64::EPSILON / 2.0;

/// Why a [`SceneSpec`] cannot be answered.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpecError {
    /// A bound is NaN or infinite.
    NonFiniteBounds,
    /// `bounds_min` exceeds `bounds_max` on some axis.
    InvertedBounds,
    /// The smallest feature is not finite and `> 0`.
    BadFeature(f32),
    /// The error budget is not finite and `≥ 0`.
    BadBudget(f32),
}

impl fmt::Display for SpecError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NonFiniteBounds => write!(f, "the scene bounds are not finite"),
            Self::InvertedBounds => write!(f, "bounds_min exceeds bounds_max"),
            Self::BadFeature(x) => {
                write!(f, "the smallest feature must be finite and > 0, not {x}")
            }
            Self::BadBudget(x) => write!(f, "the error budget must be finite and >= 0, not {x}"),
        }
    }
}

impl core::error::Error for SpecError {}

/// Recommends a tier for `spec`, or says why the description is not a scene (NaN or infinite
/// bounds, inverted bounds, a smallest feature that is not finite and positive, a budget that is
/// not finite and non-negative).
pub fn recommend(spec: &SceneSpec) -> Result<Recommendation, SpecError> {
    if !(spec.bounds_min.is_finite() && spec.bounds_max.is_finite()) {
        return Err(SpecError::NonFiniteBounds);
    }
    if spec.bounds_min.cmpgt(spec.bounds_max).any() {
        return Err(SpecError::InvertedBounds);
    }
    let feature_ok = spec.smallest_feature > 0.0 && spec.smallest_feature.is_finite();
    if !feature_ok {
        return Err(SpecError::BadFeature(spec.smallest_feature));
    }
    if !(spec.error_budget >= 0.0 && spec.error_budget.is_finite()) {
        return Err(SpecError::BadBudget(spec.error_budget));
    }
    let extent = spec
        .bounds_min
        .abs()
        .max(spec.bounds_max.abs())
        .max_element();
    let diag = (spec.bounds_max - spec.bounds_min).length();
    let scale = extent + diag;
    let f32_error = 8.0 * EPS32 * scale;
    let f32_band = 64.0 * EPS32 * scale;
    let f64_error = (2.0 * EPS64 * scale as f64) as f32;
    let f64_band = (64.0 * EPS64 * scale as f64) as f32;
    let s = spec.smallest_feature;
    let f32_fits = f32_error <= spec.error_budget && f32_band <= s / 4.0;
    let standard_range = scale <= 1e12 && s >= 1e-12;
    let watertight_range = scale <= 1e18 && s >= 1e-18;
    let representable = s >= 16.0 * (2.0 * EPS32 * extent);
    // Closed meshes need a watertight kernel at every precision.
    let f64_tier = if spec.closed_meshes {
        TierChoice::WatertightF64
    } else {
        TierChoice::F64
    };
    let (tier, meets, why) = if spec.error_budget == 0.0 {
        (TierChoice::Exact, false, Why::NoBudget)
    } else if !representable {
        (f64_tier, false, Why::InputQuantization)
    } else if f32_fits && standard_range && !spec.closed_meshes {
        (TierChoice::Standard, true, Why::StandardFits)
    } else if f32_fits && watertight_range {
        let why = if spec.closed_meshes {
            Why::ClosedMeshes
        } else {
            Why::StandardRange
        };
        (TierChoice::Watertight, true, why)
    } else {
        let fits = f64_error <= spec.error_budget && f64_band <= s / 4.0;
        (
            f64_tier,
            fits,
            if fits { Why::F32Error } else { Why::NoneFits },
        )
    };
    Ok(Recommendation {
        tier,
        meets_budget: meets,
        scale,
        f32_error,
        f64_error,
        extent,
        smallest_feature: s,
        why,
    })
}

impl fmt::Display for Recommendation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "tier {}: ", self.tier.name())?;
        match self.why {
            Why::StandardFits => write!(
                f,
                "the f32 position error bound {:.2e} at scene scale {:.2e} meets the budget and the smallest feature, and the coordinates are within the standard tier's range",
                self.f32_error, self.scale
            ),
            Why::ClosedMeshes => write!(
                f,
                "closed meshes must not leak rays, and the f32 error bound {:.2e} at scale {:.2e} meets the budget",
                self.f32_error, self.scale
            ),
            Why::StandardRange => write!(
                f,
                "the scene's coordinates or features (scale {:.2e}) are outside the standard tier's overflow/underflow range but inside the watertight tier's; error bound {:.2e}",
                self.scale, self.f32_error
            ),
            Why::F32Error => write!(
                f,
                "the f32 error bound {:.2e} at scale {:.2e} exceeds the budget or the smallest feature; f64's {:.2e} meets it",
                self.f32_error, self.scale, self.f64_error
            ),
            Why::InputQuantization => write!(
                f,
                "no tier meets the budget: features of {:.2e} are narrower than 16 ulps of coordinates of {:.2e}, so the f32 inputs have already lost their shape; translate the scene towards the origin (f64 is the most accurate on what is left)",
                self.smallest_feature, self.extent
            ),
            Why::NoBudget => write!(
                f,
                "no error budget to spend: the exact tier decides every hit/miss exactly for the f32 inputs (watertight by construction); reported positions still carry the f32 error bound {:.2e} at scale {:.2e}",
                self.f32_error, self.scale
            ),
            Why::NoneFits => write!(
                f,
                "no tier meets the budget: even f64's error bound {:.2e} at scale {:.2e} is too large; f64 is the most accurate",
                self.f64_error, self.scale
            ),
        }
    }
}
