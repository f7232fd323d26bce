//! Ray-sphere kernels, one file per algorithm: [`stable`] (the numerically stable quadratic of
//! Ray Tracing Gems ch. 7) and [`naive`] (the textbook discriminant); [`closest_point`] answers
//! point queries, [`box_overlap`] box queries.

pub mod box_overlap;
pub mod closest_point;
pub mod naive;
pub mod stable;
