//! The host's side of a stored tree: built with an allocator and written as the
//! words [`job::parse`](super::job::parse) reads (the build script stores them for the firmware;
//! the host's check reads the same words).
use octoray::bvh::Bvh8;
use octoray::prim::Primitive;

use super::job::{HEADER, MAGIC};

/// A tree over `prims` as words: the header, then the nodes, the block rows and the slot ids.
pub fn words<P: Primitive>(prims: &[P]) -> Vec<u32> {
    let bvh = Bvh8::build(prims);
    let (nodes, blocks, ids) = (bvh.nodes(), bvh.blocks(), bvh.ids());
    let mut w = Vec::with_capacity(HEADER);
    w.extend([
        MAGIC,
        nodes.len() as u32,
        blocks.len() as u32,
        ids.len() as u32,
    ]);
    w.push(prims.len() as u32);
    w.extend_from_slice(bytemuck::cast_slice(nodes));
    w.extend_from_slice(bytemuck::cast_slice(blocks));
    w.extend_from_slice(ids);
    w
}
