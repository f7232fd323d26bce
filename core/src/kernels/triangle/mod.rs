//! Ray-triangle kernels, one file per algorithm: [`moller_trumbore`] (the standard tier, and
//! its culling form) and [`watertight`] (Woop, Benthin and Wald 2013).

pub mod exact;
pub mod moller_trumbore;
pub mod watertight;
