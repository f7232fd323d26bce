//! Whole scenes: the scene sets and their rays, the systems that trace them, and the scene and
//! counts reports built from typed rows.
//!
//! A report row is a [`row::Row`] (rays, query, traversal, system); each system's built scene
//! implements [`trace::Traces`]; [`section`] measures one scene into a [`section::Section`] and
//! [`markdown`] writes it. Adding a peer: a wrapper that builds its scene and implements
//! `Traces`, a [`row::System`] variant with its label and rows, and a line in
//! [`section::measure`].

pub mod chart;
pub mod counts;
pub mod embree;
pub mod instancing;
pub mod instancing_report;
pub mod markdown;
pub mod model_report;
pub mod peers;
pub mod row;
pub mod section;
pub mod sets;
pub mod targets;
pub mod timing;
pub mod trace;
