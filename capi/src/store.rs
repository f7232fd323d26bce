//! A scene loaded from bytes: its words (owned) and the validated view of them
//! ([`SceneRef::from_words`]).
use octoray::prim::{PackedSphere, PackedTriangle, VertexTriangle};
use octoray::scene::SceneRef;

use crate::{OctorayTier, View};

/// A loaded scene's words and the view that borrows them.
pub struct Loaded {
    /// The words, from `Box::into_raw`; freed in `drop`.
    words: *mut [u32],
    /// Borrows `words` (it never outlives them: it is dropped with `self`, and [`Loaded::view`]
    /// lends it only for the length of a borrow of `self`).
    view: StaticView,
}

enum StaticView {
    Packed(SceneRef<'static, PackedTriangle, PackedSphere>),
    Vertex(SceneRef<'static, VertexTriangle, PackedSphere>),
}

impl Loaded {
    /// Copies `bytes` (little-endian words) and validates them as a scene for `tier`'s layout.
    pub fn new(bytes: &[u8], tier: OctorayTier) -> Result<Self, String> {
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
        let view = match tier {
            OctorayTier::Standard => SceneRef::from_words(words).map(StaticView::Packed),
            _ => SceneRef::from_words(words).map(StaticView::Vertex),
        };
        match view {
            Ok(view) => Ok(Self { words: raw, view }),
            Err(e) => {
                // SAFETY: `raw` came from `Box::into_raw` above; its only borrow, `words`, is
                // not used past this point.
                drop(unsafe { Box::from_raw(raw) });
                Err(e.to_string())
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
