//! Rays against a renderer's scene of geometries and instances ([`SceneRef`] through
//! [`Trace`], or through a [`Tracer`] that fixes the tiers and the lane width once): the walks of [`crate::tree`] on two levels, triangles and spheres in one query,
//! masks, and the geometry and instance in every hit; its contract is
//! [`octoray_core::scene`]'s.

mod enter;
mod instances;
mod masks;
mod points;
mod region;
mod tracer;

pub use crate::tree::point::Place;
pub use instances::Trace;
pub use masks::RayMasks;
#[cfg(feature = "alloc")]
#[doc(inline)]
pub use octoray_core::scene::Scene;
#[doc(inline)]
pub use octoray_core::scene::{
    Geometry, Instance, InstanceBox, InstancePath, Level, Member, SceneError, SceneParts, SceneRef,
    SceneTree, Transform, TreeParts, TreeRef, INSTANCES, MAX_CONDITION, MAX_INSTANCE_LEVELS,
    SPHERES, TRIANGLES,
};
pub use tracer::Tracer;

/// The one-tree walks' former paths, kept this release; they are [`crate::tree`]'s.
#[doc(hidden)]
pub use crate::tree::{
    closest, closest_packet, closest_packet_with, closest_ray, closest_ray_with, closest_t_packet,
    closest_with, occluded, occluded_packet, occluded_packet_with, occluded_ray, occluded_ray_with,
    occluded_with,
};
