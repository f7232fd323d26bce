//! Ray-triangle kernels, one file per algorithm: [`moller_trumbore`] (the standard tier, and
//! its culling form), [`moller_trumbore_fast`] (the fast tier), [`watertight`] (Woop, Benthin
//! and Wald 2013).

pub mod moller_trumbore;
pub mod moller_trumbore_fast;
pub mod watertight;
