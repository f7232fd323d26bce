//! What a query meets on entering an instance: [`enter`], shared by the ray walks and the point
//! walks.

use crate::tree::leaf::Members;
use octoray_core::bvh::Bvh8Ref;
use octoray_core::prim::Primitive;
use octoray_core::scene::{Instance, Level, SceneRef, TreeRef};

/// A tree of geometries, by kind.
pub(super) enum Geometries<'a, T, S> {
    Triangles(Bvh8Ref<'a, T>),
    Spheres(Bvh8Ref<'a, S>),
}

/// What a query meets on entering an instance its masks admit.
pub(super) enum Entered<'a, T, S> {
    /// A tree of geometries, with what the leaves need to name each hit (geometry, instance
    /// path, members).
    Tree(Geometries<'a, T, S>, (u32, u32, Members<'a>)),
    /// A group, with the mask and first path below it.
    Group(Level<'a>, u32, u32),
}

/// Instance `inst` of `scene` and what it places, entered from a level whose mask (the query's
/// and the instances' above) is `mask` and whose first instance path is `path`, when the masks
/// admit it: the instance's (and a single geometry's, or a group's) before the tree is entered;
/// in a tree of several geometries, each geometry's at its hits.
#[cfg_attr(not(debug_assertions), inline(always))]
#[allow(clippy::type_complexity)]
pub(super) fn enter<'a, T: Primitive, S: Primitive>(
    scene: &SceneRef<'a, T, S>,
    mask: u32,
    path: u32,
    inst: u32,
) -> Option<(&'a Instance, Entered<'a, T, S>)> {
    let (i, tree) = scene.instance_tree(inst)?;
    let mask = i.mask & mask;
    let path = path.wrapping_add(i.path);
    let (tree, members) = match tree {
        TreeRef::Triangles(b, m) => (Geometries::Triangles(b), m),
        TreeRef::Spheres(b, m) => (Geometries::Spheres(b), m),
        TreeRef::Instances(level) => {
            return (level.mask & mask != 0).then_some((i, Entered::Group(level, mask, path)));
        }
    };
    let geoms = scene.geometries();
    let place = if let [one] = members {
        let g = geoms.get(one.geom as usize)?;
        if g.mask & mask == 0 {
            return None;
        }
        (one.geom, path, Members::ONE)
    } else {
        if mask == 0 {
            return None;
        }
        let all_admitted = scene
            .trees()
            .get(i.tree as usize)
            .is_some_and(|t| t.mask() & mask != 0);
        (
            0,
            path,
            Members {
                members,
                geoms,
                mask,
                all_admitted,
            },
        )
    };
    Some((i, Entered::Tree(tree, place)))
}
