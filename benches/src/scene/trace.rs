//! What the scene report times: a system's built scene tracing a slice of rays, for a query, by
//! a traversal. octoray's trees implement it here, each peer beside its wrapper.

use crate::scene::row::{Query, Traversal};
use crate::scene::sets::{
    batch_closest, packets_any, packets_closest, singles_any, singles_closest,
};
use octoray::bvh::Bvh8Ref;
use octoray::kernels::Kernel;
use octoray::prim::Ray;
use std::marker::PhantomData;
use wide::{f32x16, f32x8};

/// A built scene the scene report traces.
pub trait Traces {
    /// Traces `rays` for `query` by `traversal` and returns how many hit (or are occluded);
    /// `None` for a query and traversal the system does not offer.
    fn trace(&self, query: Query, traversal: Traversal, rays: &[Ray]) -> Option<u64>;
}

/// An octoray tree traced with kernel `K` (packets of 8 and 16 lanes; single rays and the batch
/// call at 8).
pub struct OctorayTree<'a, K, P> {
    tree: Bvh8Ref<'a, P>,
    kernel: PhantomData<K>,
}

impl<'a, K, P> OctorayTree<'a, K, P>
where
    K: Kernel<f32x8, Prim = P> + Kernel<f32x16, Prim = P>,
{
    /// `tree` traced with `K`.
    pub fn new(tree: Bvh8Ref<'a, P>) -> Self {
        Self {
            tree,
            kernel: PhantomData,
        }
    }
}

impl<K, P> Traces for OctorayTree<'_, K, P>
where
    K: Kernel<f32x8, Prim = P> + Kernel<f32x16, Prim = P>,
{
    fn trace(&self, query: Query, traversal: Traversal, rays: &[Ray]) -> Option<u64> {
        let t = self.tree;
        Some(match (query, traversal) {
            (Query::Closest, Traversal::Packet8) => packets_closest::<f32x8, K>(t, rays),
            (Query::Closest, Traversal::Packet16) => packets_closest::<f32x16, K>(t, rays),
            (Query::Closest, Traversal::Single) => singles_closest::<f32x8, K>(t, rays),
            (Query::Closest, Traversal::Batch) => batch_closest::<f32x8, K>(t, rays),
            (Query::Any, Traversal::Packet8) => packets_any::<f32x8, K>(t, rays),
            (Query::Any, Traversal::Packet16) => packets_any::<f32x16, K>(t, rays),
            (Query::Any, Traversal::Single) => singles_any::<f32x8, K>(t, rays),
            (Query::Any, Traversal::Batch) => return None,
        })
    }
}
