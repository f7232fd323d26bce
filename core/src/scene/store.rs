//! A scene stored as words: its slices behind a header, to write to a file and read back with
//! [`SceneRef::from_words`] (validated; no copy, no allocator).
use super::{Geometry, Instance, Member, SceneError, SceneParts, SceneRef, SceneTree, TreeParts};
use crate::bvh::Bvh8Node;
use crate::prim::{Primitive, BLOCK};

/// The first word ("o8s5").
const MAGIC: u32 = u32::from_le_bytes(*b"o8s5");
/// Sections, in order: the triangle trees' nodes, blocks, ids; the sphere trees' nodes,
/// blocks, ids; geometries, trees, members, instances; the top tree's nodes, blocks, ids; the
/// unbounded instances.
const SECTIONS: usize = 14;
/// Words before the sections: the magic, the two layouts' words per primitive and their tags
/// ([`Primitive::TAG`]), one element count per section.
const HEADER: usize = 5 + SECTIONS;

/// Words per element of each section.
const fn element_words() -> [usize; SECTIONS] {
    let node = size_of::<Bvh8Node>() / 4;
    [
        node,
        BLOCK,
        1,
        node,
        BLOCK,
        1,
        size_of::<Geometry>() / 4,
        size_of::<SceneTree>() / 4,
        size_of::<Member>() / 4,
        size_of::<Instance>() / 4,
        node,
        BLOCK,
        1,
        1,
    ]
}

/// Words as a slice of plain data, when they hold whole elements.
fn cast<T: bytemuck::Pod>(s: &[u32]) -> Result<&[T], SceneError> {
    bytemuck::try_cast_slice(s).map_err(|_| SceneError::BadWords("a section is not whole"))
}

impl<'a> SceneParts<'a> {
    /// The slices as the sections of a stored scene, in order, as words.
    fn sections(&self) -> [&'a [u32]; SECTIONS] {
        [
            bytemuck::cast_slice(self.triangles.nodes),
            bytemuck::cast_slice(self.triangles.blocks),
            self.triangles.ids,
            bytemuck::cast_slice(self.spheres.nodes),
            bytemuck::cast_slice(self.spheres.blocks),
            self.spheres.ids,
            bytemuck::cast_slice(self.geometries),
            bytemuck::cast_slice(self.trees),
            bytemuck::cast_slice(self.members),
            bytemuck::cast_slice(self.instances),
            bytemuck::cast_slice(self.top.nodes),
            bytemuck::cast_slice(self.top.blocks),
            self.top.ids,
            self.unbounded,
        ]
    }

    /// The scene's length in 32-bit words, every slice counted (what [`SceneRef::to_words`]
    /// stores after its header): the default budget of [`SceneRef::new`].
    pub fn words(&self) -> u64 {
        self.sections().iter().map(|s| s.len() as u64).sum()
    }
}

impl<'a, T: Primitive, S: Primitive> SceneRef<'a, T, S> {
    /// The scene as words: a header (a magic word, `T::WORDS`, `S::WORDS`, `T::TAG`, `S::TAG`,
    /// each slice's length), then every slice of [`SceneRef::parts`] in turn. Write them
    /// little-endian to store the scene; [`SceneRef::from_words`] reads them back.
    #[cfg(feature = "alloc")]
    pub fn to_words(&self) -> alloc::vec::Vec<u32> {
        let p = self.parts();
        let sections = p.sections();
        let total = HEADER + sections.iter().map(|s| s.len()).sum::<usize>();
        let mut out = alloc::vec::Vec::with_capacity(total);
        out.extend([MAGIC, T::WORDS as u32, S::WORDS as u32, T::TAG, S::TAG]);
        for (s, e) in sections.iter().zip(element_words()) {
            out.push((s.len() / e) as u32);
        }
        for s in sections {
            out.extend_from_slice(s);
        }
        out
    }

    /// Reads a scene stored by [`SceneRef::to_words`] in place and validates it as
    /// [`SceneRef::new`] does (the default budget of per-ray work included): total and linear
    /// in the words' length, whatever they hold.
    ///
    /// # Errors
    /// [`SceneError::BadWords`] when the header is not one of a scene of layouts `T` and `S` or
    /// the sections do not fill the words exactly; otherwise what [`SceneRef::new`] finds.
    pub fn from_words(words: &'a [u32]) -> Result<Self, SceneError> {
        Self::new(Self::cut(words)?)
    }

    /// [`SceneRef::from_words`] with the caller's budget of per-ray work, as
    /// [`SceneRef::new_bounded`].
    ///
    /// # Errors
    /// As [`SceneRef::from_words`].
    pub fn from_words_bounded(words: &'a [u32], max_entries: u64) -> Result<Self, SceneError> {
        Self::new_bounded(Self::cut(words)?, max_entries)
    }

    /// The slices of stored words (not validated beyond the header and the sections' lengths).
    fn cut(words: &'a [u32]) -> Result<SceneParts<'a>, SceneError> {
        let header = words
            .get(..HEADER)
            .ok_or(SceneError::BadWords("shorter than the header"))?;
        if header[0] != MAGIC {
            return Err(SceneError::BadWords("not a stored octoray scene"));
        }
        if header[1..5] != [T::WORDS as u32, S::WORDS as u32, T::TAG, S::TAG] {
            return Err(SceneError::BadWords("stored for other primitive layouts"));
        }
        let mut at = HEADER;
        let mut cut: [&[u32]; SECTIONS] = [&[]; SECTIONS];
        for (i, e) in element_words().into_iter().enumerate() {
            let end = (header[5 + i] as usize)
                .checked_mul(e)
                .and_then(|n| at.checked_add(n))
                .filter(|&end| end <= words.len())
                .ok_or(SceneError::BadWords("a section runs past the end"))?;
            cut[i] = &words[at..end];
            at = end;
        }
        if at != words.len() {
            return Err(SceneError::BadWords("words past the last section"));
        }
        let tree = |i: usize| -> Result<TreeParts<'a>, SceneError> {
            Ok(TreeParts {
                nodes: cast(cut[i])?,
                blocks: cast(cut[i + 1])?,
                ids: cut[i + 2],
            })
        };
        Ok(SceneParts {
            triangles: tree(0)?,
            spheres: tree(3)?,
            geometries: cast(cut[6])?,
            trees: cast(cut[7])?,
            members: cast(cut[8])?,
            instances: cast(cut[9])?,
            top: tree(10)?,
            unbounded: cut[13],
        })
    }
}
