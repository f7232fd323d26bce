//! Rays against one tree ([`Bvh8Ref`]): the walks, generic over the kernel tier `K` and the
//! lane width `L`. A renderer's scene of geometries and instances walks with the same code on
//! two levels ([`crate::scene`]).
//!
//! | call | rays | how |
//! |---|---|---|
//! | [`closest_ray`], [`occluded_ray`] | one | one `f32x8` box test per node (its eight children, on the entry and exit faces picked once per ray); the children hit gathered with one shuffle in the node's order for the ray's direction octant ([`Bvh8Node::order`](octoray_core::bvh::Bvh8Node::order)), the first visited next and the rest kept as one stack entry; closest hit in that near-first order, occlusion from the last slot down; leaves tested a SoA block of [`BLOCK`] primitives at a time |
//! | [`closest_packet`], [`closest_t_packet`], [`occluded_packet`] | `L::LANES` | the packet's active mask goes down the tree together, children visited near-first by the packet's entry distance (occlusion: in any order); a coherent f32 packet (one direction octant) first tests a node's eight boxes against its frustum in one `f32x8` test and lane by lane only the children that pass; a packet of 16, or of 8 without a frustum, continues ray by ray below a node that at most 2 of its lanes reach (hybrid traversal); a coherent packet of 8 stays a packet to the end |
//! | [`closest`], [`occluded`] | any slice | packets where a packet's rays share a direction octant (coherent), single rays elsewhere |
//!
//! Each but `closest_t_packet` has a `_with` twin that takes a [`HitFilter`] (alpha testing,
//! decals, shadow catchers): a closure sees each candidate hit (primitive, `t`, `u`, `v`, which
//! ray) and accepts or rejects it; a rejected hit neither counts nor shortens the ray. Without a
//! filter the walks are the `_with` walks at [`AcceptAll`], whose checks compile away.
//!
//! # Contract
//! The answers equal the brute-force queries of [`octoray_core::query`] over the caller's slice,
//! bit for bit (hit/miss, `t`, `u`, `v`, primitive index), with the same tie rule: among hits
//! with equal `t`, the lowest primitive index wins. That holds because every box test is
//! conservative: a box is skipped only when no kernel can report a hit inside it, including hits
//! its rounding places slightly outside the exact primitive (the boxes carry a slack of
//! [`SLACK`](octoray_core::bvh::SLACK), 2⁻¹⁷ of the coordinates' magnitude, ≈ 128 ulp, and the
//! ray's origin adds its own; the slab test's roundings are covered by reciprocals widened by 2⁻²⁰).
//! A float tier's `t` can err by more than that slack (the kernels' contracts allow
//! `8·ε·max(t, reach)/(|cos θ|·sin α)`: a ray meeting a triangle at |cos θ|·sin α ≲ 1/16), and
//! could then lie before a box that holds the primitive; every kernel raises such a `t` to the
//! ray's entry into the primitive's own box (and a kernel that decides `t ≥ t_min` on its
//! rounded `t` reports no hit where the ray leaves that box before `t_min`), so no box that
//! holds a primitive whole is entered after a hit reported on it or left before `t_min`, and the
//! walk's culling by its best `t` and by `t_min` equals brute force. The
//! exception is a tree with spatial splits: a part's box holds only part of the primitive and
//! can be entered after such a `t`; if another hit lies within that `t` error of it (or
//! `t_min`/`t_max` does), the tree may report the other: a hit either way, within the tier's
//! `t` error of brute force's (the exact tier's `t`, within an ulp, is not affected). The same holds where the kernels
//! underflow (`ρ²·t ≲ 1e-30`, see the watertight contract). The naive sphere tier is not sound
//! far from a sphere (its contract): a false hit it reports there lies outside every box, and
//! the tree does not report it.
//!
//! With a filter that answers as a function of the candidate alone, the `_with` walks equal
//! brute force over the hits the filter accepts, under the same contract and tie rule.
//!
//! # Untrusted trees
//! On any tree [`Bvh8Ref::new`] accepted, built or read from untrusted bytes, every call here is
//! total: no panic (but the documented length checks of [`closest`] and [`occluded`]), each node
//! visited and each leaf slot tested at most once per ray, and every reported `prim` below
//! [`Bvh8Ref::prims`].

#[cfg(doc)]
use octoray_core::{
    bvh::Bvh8Ref,
    hit::{AcceptAll, HitFilter},
    prim::BLOCK,
};

pub(crate) mod all_hits;
pub(crate) mod batch;
pub(crate) mod epilog;
pub(crate) mod leaf;
pub(crate) mod packet;
pub(crate) mod point;
mod queries;
pub(crate) mod region;
pub(crate) mod single;
pub(crate) mod slab;
#[cfg(feature = "triangle")]
pub(crate) mod solid;
#[cfg(all(feature = "triangle", feature = "alloc"))]
mod winding;

#[cfg(test)]
mod box_test;

pub use all_hits::{all_hits, all_hits_ray, hit_order, AllHits};
pub use point::{closest_point, nearest_within, PointHit};
pub use queries::{
    closest, closest_packet, closest_packet_with, closest_ray, closest_ray_with, closest_t_packet,
    closest_with, occluded, occluded_packet, occluded_packet_with, occluded_ray, occluded_ray_with,
    occluded_with,
};
pub use region::overlapping;
#[cfg(feature = "triangle")]
pub use solid::crossings_ray;
#[cfg(all(feature = "triangle", feature = "alloc"))]
pub use solid::{contains, signed_distance, winding_number};
#[cfg(all(feature = "triangle", feature = "alloc"))]
pub use winding::generalized_winding_number;
