//! The box query on a scene: each level's tree walked with the world box carried into its space
//! (conservatively: its corners mapped, then widened past the roundings), each candidate tested
//! in world space (its primitive carried there in f64).

use super::enter::{enter, Entered, Geometries};
use crate::tree::all_hits::{insert_sorted, AllHits};
use crate::tree::leaf::Members;
use crate::tree::point::Place;
use crate::tree::region::box_walk;
use octoray_core::bvh::{Bvh8Ref, PAD};
use octoray_core::glam::Vec3;
use octoray_core::kernels::MeetsBox;
use octoray_core::prim::{Affine64, BlockLane, Primitive, BLOCK};
use octoray_core::scene::{Level, SceneRef, Transform};

/// One space a box walk passes through: the maps between it and the world, and the world box's
/// bounds there (f32, holding the box's image).
struct Space {
    /// This space → world.
    to_world: Affine64,
    /// World → this space.
    to_here: Affine64,
    lo: [f32; 3],
    hi: [f32; 3],
}

/// The largest f32 at or below `x` (−inf below f32's range).
fn f32_down(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) > x {
        f.next_down()
    } else {
        f
    }
}

/// The smallest f32 at or above `x` (+inf above f32's range).
fn f32_up(x: f64) -> f32 {
    -f32_down(-x)
}

impl Space {
    /// The world, with the box `[lo, hi]`.
    fn world(lo: [f64; 3], hi: [f64; 3]) -> Self {
        Self {
            to_world: Affine64::IDENTITY,
            to_here: Affine64::IDENTITY,
            lo: lo.map(f32_down),
            hi: hi.map(f32_up),
        }
    }

    /// The space an instance with transform `t` (from this space into its own) leads to, for
    /// the world box `[lo, hi]`; `None` when its map is singular (its primitives have no world
    /// image) or the box's image is not finite.
    fn enter(&self, t: &Transform, lo: [f64; 3], hi: [f64; 3]) -> Option<Self> {
        let a = t.to_f64();
        let to_here = self.to_here.then(&a);
        let to_world = a.inverse()?.then(&self.to_world);
        if !lo.iter().chain(&hi).all(|x| x.is_finite()) {
            // An unbounded box: unbounded in every space.
            let (lo, hi) = ([f32::NEG_INFINITY; 3], [f32::INFINITY; 3]);
            return Some(Self {
                to_world,
                to_here,
                lo,
                hi,
            });
        }
        let (mut l, mut h) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for corner in 0..8 {
            let p: [f64; 3] =
                core::array::from_fn(|k| if corner >> k & 1 == 1 { hi[k] } else { lo[k] });
            let q = to_here.apply(p);
            for k in 0..3 {
                l[k] = l[k].min(q[k]);
                h[k] = h[k].max(q[k]);
            }
        }
        // The map's roundings: a few units of 2⁻⁵² of its terms, taken as 2⁻⁴⁰ of their sum.
        let big = |p: [f64; 3]| p.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let terms = to_here.stretch() * big(lo).max(big(hi)) + big(to_here.t);
        let slack = terms / 1_099_511_627_776.0;
        if !(l.iter().chain(&h).all(|x| x.is_finite()) && slack.is_finite()) {
            return None;
        }
        Some(Self {
            to_world,
            to_here,
            lo: l.map(|x| f32_down(x - slack)),
            hi: h.map(|x| f32_up(x + slack)),
        })
    }
}

/// A box query's walk through a scene: the world box, the cursor and the answers so far.
struct Boxes<'s, 'a, 'o, T, S> {
    scene: &'s SceneRef<'a, T, S>,
    lo: [f64; 3],
    hi: [f64; 3],
    after: Option<Place>,
    out: &'o mut [Place],
    found: AllHits,
}

impl<T: MeetsBox, S: MeetsBox> Boxes<'_, '_, '_, T, S> {
    /// A level (under `mask`, paths from `path`, in `space`): its tree, then its unbounded
    /// instances.
    fn level(&mut self, level: Level<'_>, mask: u32, path: u32, space: &Space) {
        box_walk(level.top.nodes(), 0, space.lo, space.hi, |first, count| {
            for slot in first as usize..(first as usize).saturating_add(count as usize) {
                if let Some(part) = level.part(slot) {
                    self.instance(mask, path, space, part);
                }
            }
        });
        for &inst in level.unbounded {
            self.instance(mask, path, space, (inst, 0));
        }
    }

    /// The part of instance `inst` that starts at `node` of its tree, when the masks admit it
    /// and its map is invertible.
    fn instance(&mut self, mask: u32, path: u32, space: &Space, (inst, node): (u32, u32)) {
        let Some((i, entered)) = enter(self.scene, mask, path, inst) else {
            return;
        };
        let Some(here) = space.enter(&i.transform, self.lo, self.hi) else {
            return;
        };
        match entered {
            Entered::Tree(Geometries::Triangles(b), place) => self.tree(b, place, node, &here),
            Entered::Tree(Geometries::Spheres(b), place) => self.tree(b, place, node, &here),
            Entered::Group(level, mask, path) => self.level(level, mask, path, &here),
        }
    }

    /// An instance's tree `bvh` from `node`, in `space`: each primitive in a leaf the box's
    /// image reaches, tested in world space.
    fn tree<P: MeetsBox>(
        &mut self,
        bvh: Bvh8Ref<'_, P>,
        (geom, path, members): (u32, u32, Members<'_>),
        node: u32,
        space: &Space,
    ) {
        let identity = space.to_world == Affine64::IDENTITY;
        let (lo, hi) = (self.lo, self.hi);
        box_walk(bvh.nodes(), node, space.lo, space.hi, |first, count| {
            let end = (first as usize)
                .saturating_add(count as usize)
                .min(bvh.ids().len());
            for slot in first as usize..end {
                let id = bvh.ids()[slot];
                if id == PAD {
                    continue;
                }
                let Some((geom, prim)) = members.locate(geom, id) else {
                    continue;
                };
                let place = Place {
                    inst: path,
                    geom,
                    prim,
                };
                if self.after.is_some_and(|a| place <= a) {
                    continue;
                }
                let words = BlockLane::new::<P>(bvh.block_of(slot), slot % BLOCK);
                let meets = if identity {
                    P::meets_box(&words, lo, hi)
                } else {
                    P::meets_box_mapped(&words, &space.to_world, &space.to_here, lo, hi)
                };
                if meets {
                    insert_sorted(self.out, &mut self.found, place, Place::cmp);
                }
            }
        });
    }
}

/// The primitives of `scene` under `mask` that meet the world box `[lo, hi]`, as
/// [`crate::scene::Trace::overlapping`] answers.
pub(super) fn scene_boxes<T: MeetsBox + Primitive, S: MeetsBox + Primitive>(
    scene: &SceneRef<'_, T, S>,
    (lo, hi): (Vec3, Vec3),
    mask: u32,
    after: Option<Place>,
    out: &mut [Place],
) -> AllHits {
    let mut walk = Boxes {
        scene,
        lo: lo.to_array().map(f64::from),
        hi: hi.to_array().map(f64::from),
        after,
        out,
        found: AllHits {
            stored: 0,
            complete: true,
        },
    };
    if !lo.cmple(hi).all() {
        return walk.found;
    }
    let space = Space::world(walk.lo, walk.hi);
    walk.level(scene.world(), mask, 0, &space);
    walk.found
}
