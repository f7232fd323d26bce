//! octoray for Python: a triangle mesh built from numpy arrays and its batched queries (first
//! hit, occlusion, every hit, exact crossing counts, containment, winding numbers, closest
//! points, signed distance), each releasing the GIL and spread over threads.
//!
//! The Python package (`octoray/__init__.py`) normalises dtypes and shapes; this module checks
//! them again, so that no array from Python can make it panic, read out of bounds or run long.
#![deny(unsafe_code)] // PyO3's macros expand to their own audited unsafe code, none of ours.

mod arrays;
mod mesh;
mod scene;
mod tier;

use pyo3::prelude::*;

/// The native module: `octoray._octoray`.
#[pymodule]
fn _octoray(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<mesh::Mesh>()?;
    m.add_class::<scene::Scene>()?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
