//! How many random cases a test runs: its own count scaled by the environment variable
//! `OCTORAY_CASES` (a factor; unset means 1). The emulated ISAs' slices (`.ci/cross.sh`) run
//! with a fraction of the cases, a long local run with a multiple. Fixed data (the determinism
//! digest, the seed problems, named cases) is never scaled.

/// The scale factor: `OCTORAY_CASES` when it is a positive finite number, else 1.
pub fn scale() -> f64 {
    std::env::var("OCTORAY_CASES")
        .ok()
        .and_then(|s| s.trim().parse::<f64>().ok())
        .filter(|f| f.is_finite() && *f > 0.0)
        .unwrap_or(1.0)
}

/// `n` cases scaled by [`scale`], at least 1.
pub fn cases(n: usize) -> usize {
    ((n as f64 * scale()).round() as usize).max(1)
}

/// A proptest configuration of `n` cases scaled by [`scale`].
pub fn proptest_config(n: u32) -> proptest::test_runner::Config {
    proptest::test_runner::Config::with_cases(cases(n as usize) as u32)
}
