//! The tiers by name.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// The triangle tier a mesh or a scene answers rays with.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Tier {
    /// Möller–Trumbore: stated error bounds, rays may slip through shared edges.
    Standard,
    /// No ray escapes a closed mesh.
    Watertight,
    /// Every hit or miss exact for the f32 inputs.
    Exact,
}

impl Tier {
    /// The tier named `name`, or a `ValueError`.
    pub fn parse(name: &str) -> PyResult<Self> {
        match name {
            "standard" => Ok(Self::Standard),
            "watertight" => Ok(Self::Watertight),
            "exact" => Ok(Self::Exact),
            _ => Err(PyValueError::new_err(format!(
                "unknown tier {name:?}: expected \"watertight\", \"exact\" or \"standard\""
            ))),
        }
    }

    /// Its name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Standard => "standard",
            Self::Watertight => "watertight",
            Self::Exact => "exact",
        }
    }
}
