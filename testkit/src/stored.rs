//! A stored scene's tree records word by word, as hostile data edits them: a [`SceneTree`] is
//! 14 little-endian words in the stored format ([`SceneRef::to_words`]), in this order. The
//! library keeps the record's fields private; the tests that corrupt a stored scene name the
//! words here.
//!
//! [`SceneRef::to_words`]: octoray::scene::SceneRef::to_words

use octoray::scene::SceneTree;

/// `TRIANGLES`, `SPHERES` or `INSTANCES`.
pub const KIND: usize = 0;
/// Its members' primitives (a group: its instances).
pub const PRIMS: usize = 1;
/// Its root's index in the nodes of its kind.
pub const FIRST_NODE: usize = 2;
/// Its number of nodes.
pub const NODES: usize = 3;
/// Its first block in the blocks of its kind.
pub const FIRST_BLOCK: usize = 4;
/// Its number of blocks.
pub const BLOCKS: usize = 5;
/// Its first member (a group: its first instance).
pub const FIRST_MEMBER: usize = 6;
/// Its number of members.
pub const MEMBERS: usize = 7;
/// Its mask.
pub const MASK: usize = 8;
/// Instance levels below an instance of it.
pub const LEVELS: usize = 9;
/// Instance paths through one instance of it.
pub const PATHS: usize = 10;
/// Relative origin slack of its box tests (an `f32`'s bits).
pub const SLACK: usize = 11;
/// A group's first entry in the unbounded list.
pub const FIRST_UNBOUNDED: usize = 12;
/// A group's number of unbounded entries.
pub const UNBOUNDED: usize = 13;

/// The record as its 14 words.
pub fn words(t: &SceneTree) -> [u32; 14] {
    bytemuck::cast(*t)
}

/// Word `i` of the record, to read or to corrupt.
pub fn word(t: &mut SceneTree, i: usize) -> &mut u32 {
    &mut bytemuck::cast_mut::<SceneTree, [u32; 14]>(t)[i]
}
