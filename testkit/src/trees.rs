//! Serialised trees for the untrusted-tree tests: a built tree as plain slices, the crafted
//! hostile shapes (shared subtrees, every slot on one node, chains to and past the depth limit,
//! `PAD` and out-of-range indices), random mutations of all of them, and a kernel that counts the
//! leaf tests a query makes, so a test can bound the work of a query on an accepted tree.

use crate::Rng;
use octoray::bvh::{Bvh8, Bvh8Node, EMPTY, PAD, WIDTH};
use octoray::glam::Vec3;
use octoray::hit::LanesHit;
use octoray::kernels::{Kernel, Watertight};
use octoray::lanes::Lanes;
use octoray::prim::{Primitive, RayLanes, VertexTriangle, Words, BLOCK};
use std::cell::Cell;

/// A tree as the three slices `Bvh8Ref::new` takes, and the caller's primitive count.
#[derive(Clone, Debug)]
pub struct Slices {
    /// Nodes, root first.
    pub nodes: Vec<Bvh8Node>,
    /// Primitive blocks.
    pub blocks: Vec<[f32; BLOCK]>,
    /// Block slot → caller's index.
    pub ids: Vec<u32>,
    /// The caller's primitive count.
    pub prims: usize,
}

impl Slices {
    /// A built tree's slices.
    pub fn of(tree: &Bvh8<VertexTriangle>, prims: usize) -> Self {
        Self {
            nodes: tree.nodes().to_vec(),
            blocks: tree.blocks().to_vec(),
            ids: tree.ids().to_vec(),
            prims,
        }
    }

    /// Leaf block slots (the work bound of a query: each is tested at most once per ray).
    pub fn slots(&self) -> usize {
        self.ids.len()
    }
}

/// `n` random triangles in the unit cube.
pub fn triangles(rng: &mut Rng, n: usize) -> Vec<VertexTriangle> {
    (0..n)
        .map(|_| {
            let c = rng.vec3(1.0);
            let s = libm::powf(10.0, rng.range(-2.0, -0.5));
            VertexTriangle::new(c + rng.vec3(s), c + rng.vec3(s), c + rng.vec3(s))
        })
        .collect()
}

/// A box of half-size `h` around the origin in slot `s`.
fn set_box(n: &mut Bvh8Node, s: usize, h: f32) {
    for a in 0..3 {
        (n.lo[a][s], n.hi[a][s]) = (-h, h);
    }
}

/// A chain of `n` nodes whose first `slots` slots each name the next node (the last node: leaves
/// of one triangle), boxes [−10, 10]³.
fn linked(n: usize, slots: usize) -> Slices {
    let tri = VertexTriangle::new(
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::Y,
    );
    let mut blocks = vec![[0.0; BLOCK]; VertexTriangle::WORDS];
    VertexTriangle::write_block(core::slice::from_ref(&tri), &mut blocks);
    let mut ids = vec![PAD; BLOCK];
    ids[0] = 0;
    let nodes = (0..n)
        .map(|i| {
            let mut node = Bvh8Node::EMPTY;
            for s in 0..slots {
                set_box(&mut node, s, 10.0);
                (node.child[s], node.count[s]) = if i + 1 < n { (i as u32 + 1, 0) } else { (0, 1) };
            }
            node
        })
        .collect();
    Slices {
        nodes,
        blocks,
        ids,
        prims: 1,
    }
}

/// The exponential shape: node `i`'s slots 0 and 1 both name node `i + 1` (a DAG with 2ⁿ paths);
/// the last node holds two leaves of the one triangle. Every box is [−10, 10]³.
pub fn shared_chain(n: usize) -> Slices {
    linked(n, 2)
}

/// A chain of `n` nodes, each with one inner child, the last holding a leaf of one triangle: in
/// build order, so valid exactly when `n` is within the depth limit.
pub fn chain(n: usize) -> Slices {
    linked(n, 1)
}

/// A chain of `depth` nodes, each with eight inner children entered by every ray near the
/// origin (boxes [−10, 10]³): seven empty nodes and, in the last slot, the next link; the last
/// link holds a leaf of one triangle. In build order. Every ray walks it with the fullest stack
/// a tree of that depth allows.
pub fn bushy_chain(depth: usize) -> Slices {
    let mut t = chain(1);
    let leaf = t.nodes[0];
    t.nodes.clear();
    for k in 0..depth.saturating_sub(1) {
        let mut node = Bvh8Node::EMPTY;
        for s in 0..WIDTH {
            set_box(&mut node, s, 10.0);
            (node.child[s], node.count[s]) = ((WIDTH * k + s + 1) as u32, 0);
        }
        t.nodes.push(node);
        t.nodes.extend([Bvh8Node::EMPTY; WIDTH - 1]);
    }
    t.nodes.push(leaf);
    t
}

/// The inner slots of a tree: (node, slot).
fn inner_slots(t: &Slices) -> Vec<(usize, usize)> {
    let mut v = vec![];
    for (i, n) in t.nodes.iter().enumerate() {
        for s in 0..WIDTH {
            if n.child[s] != EMPTY && n.count[s] == 0 {
                v.push((i, s));
            }
        }
    }
    v
}

/// The leaf slots of a tree: (node, slot).
fn leaf_slots(t: &Slices) -> Vec<(usize, usize)> {
    let mut v = vec![];
    for (i, n) in t.nodes.iter().enumerate() {
        for s in 0..WIDTH {
            if n.child[s] != EMPTY && n.count[s] > 0 {
                v.push((i, s));
            }
        }
    }
    v
}

fn pick<T: Copy>(rng: &mut Rng, v: &[T]) -> Option<T> {
    (!v.is_empty()).then(|| v[rng.below(v.len() as u64) as usize])
}

/// One crafted hostile change to `t`, chosen at random; what it did, for messages.
pub fn craft(rng: &mut Rng, t: &mut Slices) -> &'static str {
    let inner = inner_slots(t);
    let leaves = leaf_slots(t);
    let nn = t.nodes.len() as u32;
    match rng.below(10) {
        0 => {
            // Share a subtree: a second slot names an existing child.
            if let (Some((i, s)), Some((_, s2))) = (pick(rng, &inner), pick(rng, &inner)) {
                let (c, node) = (t.nodes[i].child[s], &mut t.nodes[i]);
                let s2 = (s2 + 1 + s) % node.len().max(1);
                (node.child[s2], node.count[s2]) = (c, 0);
            }
            "shared subtree"
        }
        1 => {
            // Every slot of a node on one node.
            let i = rng.below(nn as u64) as usize;
            let c = (i as u32 + 1 + rng.below(3) as u32).min(nn.saturating_sub(1));
            let node = &mut t.nodes[i];
            for s in 0..WIDTH {
                set_box(node, s, 1e3);
                (node.child[s], node.count[s]) = (c, 0);
            }
            "every slot on one node"
        }
        2 => {
            // Two leaves on one range.
            if let (Some((i, s)), Some((j, r))) = (pick(rng, &leaves), pick(rng, &leaves)) {
                let (c, k) = (t.nodes[i].child[s], t.nodes[i].count[s]);
                (t.nodes[j].child[r], t.nodes[j].count[r]) = (c, k);
            }
            "shared leaf range"
        }
        3 => {
            // PAD or an out-of-range index inside a leaf.
            if let Some((i, s)) = pick(rng, &leaves) {
                let at = t.nodes[i].child[s] as usize
                    + rng.below(u64::from(t.nodes[i].count[s])) as usize;
                if let Some(id) = t.ids.get_mut(at) {
                    *id = match rng.below(3) {
                        0 => PAD,
                        1 => t.prims as u32,
                        _ => u32::MAX - 1,
                    };
                }
            }
            "PAD or out-of-range index"
        }
        4 => {
            // A leaf as large as all the slots.
            if let Some((i, s)) = pick(rng, &leaves) {
                (t.nodes[i].child[s], t.nodes[i].count[s]) = (0, t.ids.len() as u32);
            }
            "leaf over every slot"
        }
        5 => {
            // Swap two nodes' contents (build order broken, a tree still).
            let (a, b) = (rng.below(nn as u64) as usize, rng.below(nn as u64) as usize);
            t.nodes.swap(a, b);
            "nodes swapped"
        }
        6 => {
            // A back edge: a cycle.
            if let Some((i, s)) = pick(rng, &inner) {
                t.nodes[i].child[s] = rng.below(i as u64 + 1) as u32;
            }
            "back edge"
        }
        7 => {
            // A used slot after an empty one, or a leaf turned inner.
            let i = rng.below(nn as u64) as usize;
            let node = &mut t.nodes[i];
            let s = rng.below(WIDTH as u64) as usize;
            if node.child[s] == EMPTY {
                (node.child[s], node.count[s]) = (rng.below(nn as u64 + 2) as u32, 0);
            } else {
                node.count[s] = 0;
            }
            "slot rewritten"
        }
        8 => {
            // Boxes: NaN, inverted, infinite.
            let i = rng.below(nn as u64) as usize;
            let s = rng.below(WIDTH as u64) as usize;
            let a = rng.below(3) as usize;
            let x =
                [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 1e30, -1e30][rng.below(5) as usize];
            if rng.below(2) == 0 {
                t.nodes[i].lo[a][s] = x;
            } else {
                t.nodes[i].hi[a][s] = x;
            }
            "box value"
        }
        _ => {
            // Random bytes of a node.
            let i = rng.below(nn as u64) as usize;
            let bytes: &mut [u8] = bytemuck::bytes_of_mut(&mut t.nodes[i]);
            for _ in 0..1 + rng.below(4) {
                let k = rng.below(bytes.len() as u64) as usize;
                bytes[k] = rng.next_u64() as u8;
            }
            "random bytes"
        }
    }
}

thread_local! {
    static LEAF_TESTS: Cell<usize> = const { Cell::new(0) };
}

/// Leaf tests made on this thread since the last call (and resets the count).
pub fn take_leaf_tests() -> usize {
    LEAF_TESTS.with(|c| c.replace(0))
}

/// The watertight tier, counting its calls: one per leaf test (a block for a single ray, a
/// primitive for a packet).
#[derive(Clone, Copy, Debug, Default)]
pub struct Counting;

impl<L: Lanes> Kernel<L> for Counting
where
    Watertight: Kernel<L, Prim = VertexTriangle>,
{
    type Prim = VertexTriangle;
    type Pre = <Watertight as Kernel<L>>::Pre;
    fn prepare(ray: &RayLanes<L>) -> Self::Pre {
        <Watertight as Kernel<L>>::prepare(ray)
    }
    fn intersect_lanes(
        ray: &RayLanes<L>,
        pre: &Self::Pre,
        prim: &<VertexTriangle as Primitive>::Lanes<L>,
    ) -> LanesHit<L> {
        LEAF_TESTS.with(|c| c.set(c.get() + 1));
        <Watertight as Kernel<L>>::intersect_lanes(ray, pre, prim)
    }
    fn intersect_words<W: Words>(ray: &RayLanes<L>, pre: &Self::Pre, words: &W) -> LanesHit<L> {
        LEAF_TESTS.with(|c| c.set(c.get() + 1));
        <Watertight as Kernel<L>>::intersect_words(ray, pre, words)
    }
}
