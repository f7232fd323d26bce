//! Ray-triangle kernels, one file per algorithm: [`moller_trumbore`] (the standard tier, and
//! its culling form), [`watertight`] (Woop, Benthin and Wald 2013), [`exact`] (its decisions made
//! exact) and [`crossing`] (the exact decisions with every tie broken once); [`closest_point`]
//! answers point queries, [`box_overlap`] box queries, [`solid_angle`] winding numbers.

pub mod box_overlap;
pub mod closest_point;
pub mod crossing;
pub mod exact;
pub mod moller_trumbore;
pub mod solid_angle;
pub mod watertight;
