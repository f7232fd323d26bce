//! Ray-sphere kernels, one file per algorithm: [`stable`] (the numerically stable quadratic of
//! Ray Tracing Gems ch. 7) and [`naive`] (the textbook discriminant).

pub mod naive;
pub mod stable;
