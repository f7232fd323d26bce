//! Stored scenes: a scene's slices as little-endian words behind a header, and a loaded scene
//! that owns its words and the validated view of them.
use octoray::bvh::Bvh8Node;
use octoray::prim::{PackedSphere, PackedTriangle, VertexTriangle, BLOCK};
use octoray::scene::{Geometry, Instance, Member, SceneParts, SceneRef, SceneTree, TreeParts};

use crate::{OctorayTier, View};

/// The first word ("o8s1").
const MAGIC: u32 = u32::from_le_bytes(*b"o8s1");
/// Sections, in order: the triangle trees' nodes, blocks, ids; the sphere trees' nodes,
/// blocks, ids; geometries, trees, members, instances; the top tree's nodes, blocks, ids; the
/// unbounded instances.
const SECTIONS: usize = 14;
/// Words before the sections: magic, tier, one element count per section.
const HEADER: usize = 2 + SECTIONS;

/// Words per element of each section.
fn element_words() -> [usize; SECTIONS] {
    let w = |bytes: usize| bytes / 4;
    let (node, block) = (w(size_of::<Bvh8Node>()), BLOCK);
    [
        node,
        block,
        1,
        node,
        block,
        1,
        w(size_of::<Geometry>()),
        w(size_of::<SceneTree>()),
        w(size_of::<Member>()),
        w(size_of::<Instance>()),
        node,
        block,
        1,
        1,
    ]
}

/// A slice of 4-byte-aligned plain data as words.
fn words_of<T: bytemuck::Pod>(s: &[T]) -> Vec<u32> {
    bytemuck::cast_slice(s).to_vec()
}

/// Words as a slice of plain data, when they hold whole elements.
fn cast<T: bytemuck::Pod>(s: &[u32]) -> Result<&[T], &'static str> {
    bytemuck::try_cast_slice(s).map_err(|_| "a section is not whole")
}

/// A committed scene's slices as words.
pub fn words(tier: OctorayTier, p: SceneParts<'_>) -> Vec<u32> {
    let tree = |t: TreeParts<'_>| [words_of(t.nodes), words_of(t.blocks), t.ids.to_vec()];
    let [tn, tb, ti] = tree(p.triangles);
    let [sn, sb, si] = tree(p.spheres);
    let [on, ob, oi] = tree(p.top);
    let sections = [
        tn,
        tb,
        ti,
        sn,
        sb,
        si,
        words_of(p.geometries),
        words_of(p.trees),
        words_of(p.members),
        words_of(p.instances),
        on,
        ob,
        oi,
        p.unbounded.to_vec(),
    ];
    let mut out = vec![MAGIC, tier as u32];
    for (s, w) in sections.iter().zip(element_words()) {
        out.push((s.len() / w) as u32);
    }
    for s in &sections {
        out.extend_from_slice(s);
    }
    out
}

/// The scene's slices cut from validated lengths (every cast checked).
fn parts(words: &[u32]) -> Result<(OctorayTier, SceneParts<'_>), &'static str> {
    let header = words.get(..HEADER).ok_or("shorter than the header")?;
    if header[0] != MAGIC {
        return Err("not a stored octoray scene");
    }
    let tier = OctorayTier::from_raw(header[1]).ok_or("unknown tier")?;
    let mut at = HEADER;
    let mut cut: [&[u32]; SECTIONS] = [&[]; SECTIONS];
    for (i, w) in element_words().into_iter().enumerate() {
        let n = (header[2 + i] as usize)
            .checked_mul(w)
            .ok_or("a section's length overflows")?;
        let end = at
            .checked_add(n)
            .filter(|&e| e <= words.len())
            .ok_or("a section runs past the end")?;
        cut[i] = &words[at..end];
        at = end;
    }
    if at != words.len() {
        return Err("bytes past the last section");
    }
    let tree = |i: usize| -> Result<TreeParts<'_>, &'static str> {
        Ok(TreeParts {
            nodes: cast(cut[i])?,
            blocks: cast(cut[i + 1])?,
            ids: cut[i + 2],
        })
    };
    Ok((
        tier,
        SceneParts {
            triangles: tree(0)?,
            spheres: tree(3)?,
            geometries: cast(cut[6])?,
            trees: cast(cut[7])?,
            members: cast(cut[8])?,
            instances: cast(cut[9])?,
            top: tree(10)?,
            unbounded: cut[13],
        },
    ))
}

/// A scene loaded from bytes: its words (owned) and the validated view of them.
pub struct Loaded {
    /// The words, from `Box::into_raw`; freed in `drop`.
    words: *mut [u32],
    /// Borrows `words` (never outlives them: it is dropped with `self`, and `view` lends it
    /// only for the length of a borrow of `self`).
    view: StaticView,
}

enum StaticView {
    Packed(SceneRef<'static, PackedTriangle, PackedSphere>),
    Vertex(SceneRef<'static, VertexTriangle, PackedSphere>),
}

impl Loaded {
    /// Copies `bytes` into words and validates them as a scene.
    pub fn new(bytes: &[u8]) -> Result<(OctorayTier, Self), String> {
        if !bytes.len().is_multiple_of(4) {
            return Err("the length is not a whole number of words".into());
        }
        let boxed: Box<[u32]> = bytes
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        let raw = Box::into_raw(boxed);
        // SAFETY: `raw` came from `Box::into_raw` just above and is freed only by `Loaded`'s
        // `drop` (or below on failure); nothing writes to it meanwhile, so a shared `'static`
        // borrow is sound for as long as `Loaded` lives, which `view` never outlives.
        let words: &'static [u32] = unsafe { &*raw };
        let checked = parts(words).map_err(String::from).and_then(|(tier, p)| {
            let view = match tier {
                OctorayTier::Standard => SceneRef::new(p).map(StaticView::Packed),
                _ => SceneRef::new(p).map(StaticView::Vertex),
            };
            view.map(|v| (tier, v))
                .map_err(|e| format!("the scene does not validate: {e:?}"))
        });
        match checked {
            Ok((tier, view)) => Ok((tier, Self { words: raw, view })),
            Err(e) => {
                // SAFETY: `raw` came from `Box::into_raw` above; the only borrow of it,
                // `words`, is not used past this point.
                drop(unsafe { Box::from_raw(raw) });
                Err(e)
            }
        }
    }

    /// The scene, for the length of a borrow of `self`.
    pub fn view(&self) -> View<'_> {
        match &self.view {
            StaticView::Packed(s) => View::Packed(*s),
            StaticView::Vertex(s) => View::Vertex(*s),
        }
    }
}

impl Drop for Loaded {
    fn drop(&mut self) {
        // SAFETY: `words` came from `Box::into_raw` in `new` and is freed only here; `view`,
        // its only borrower, is a plain copy of slices that is not used after this.
        drop(unsafe { Box::from_raw(self.words) });
    }
}
