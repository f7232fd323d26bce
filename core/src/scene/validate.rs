//! The checks that make a scene's slices a [`SceneRef`]: every count, range, tree, member list,
//! group and instance, each read once (time linear in the slices' size), every failure a
//! [`SceneError`].
use super::{
    origin_slack, sub_tree, InstanceBox, Level, SceneError, SceneParts, SceneRef, SceneTree,
    TreeParts, INSTANCES, MAX_INSTANCE_LEVELS, SPHERES, TRIANGLES,
};
use crate::bvh::{Bvh8Ref, SLACK};
use crate::prim::{Primitive, BLOCK};

/// How far the checks of the trees have read each shared slice.
struct Cursor {
    /// The next node and block of each kind's slices (triangles, spheres, groups' top trees).
    next: [(u32, u32); 3],
    /// The next member.
    member: usize,
    /// The next instance (after the world's).
    inst: usize,
    /// The next unbounded entry (after the world's).
    unbounded: usize,
}

/// The world's share of the shared slices: all that comes before the first group's.
struct World<'a> {
    /// The first group's tree, if any.
    first_group: Option<usize>,
    /// The world's instances, the first `roots` of the list.
    roots: usize,
    /// Where the world's top tree ends (node, block).
    end: (u32, u32),
    /// The world's unbounded entries, the first `unbounded` of the list.
    unbounded: usize,
    /// The world's top tree's slices.
    top: TreeParts<'a>,
}

impl<'a, T: Primitive, S: Primitive> SceneRef<'a, T, S> {
    /// [`SceneRef::new`]'s checks but the work bound.
    pub(super) fn validate(parts: SceneParts<'a>) -> Result<Self, SceneError> {
        check_counts(&parts)?;
        let world = World::find(&parts)?;
        let mut at = Cursor {
            next: [(0, 0), (0, 0), world.end],
            member: 0,
            inst: world.roots,
            unbounded: world.unbounded,
        };
        for i in 0..parts.trees.len() {
            check_tree::<T, S>(&parts, i, &mut at)?;
        }
        check_all_read::<T, S>(&parts, &at, &world)?;
        let root = world.level(&parts)?;
        Ok(Self::with_sole(parts, root))
    }
}

/// Every count fits a `u32` index and every geometry has a known kind.
fn check_counts(parts: &SceneParts<'_>) -> Result<(), SceneError> {
    if u32::try_from(parts.geometries.len()).is_err()
        || u32::try_from(parts.instances.len()).is_err()
        || u32::try_from(parts.trees.len()).is_err()
        || u32::try_from(parts.unbounded.len()).is_err()
    {
        return Err(SceneError::TooMany);
    }
    match parts
        .geometries
        .iter()
        .position(|g| g.kind != TRIANGLES && g.kind != SPHERES)
    {
        Some(at) => Err(SceneError::BadKind { at }),
        None => Ok(()),
    }
}

impl<'a> World<'a> {
    /// The world's share: up to the first group's instances, unbounded entries and top tree.
    fn find(parts: &SceneParts<'a>) -> Result<Self, SceneError> {
        let first_group = parts.trees.iter().position(|t| t.kind == INSTANCES);
        let bad = SceneError::BadGroup {
            tree: first_group.unwrap_or(0),
        };
        let Some(g) = first_group.map(|g| &parts.trees[g]) else {
            let nodes = u32::try_from(parts.top.nodes.len()).map_err(|_| SceneError::TooMany)?;
            let blocks =
                u32::try_from(parts.top.ids.len() / BLOCK).map_err(|_| SceneError::TooMany)?;
            return Ok(Self {
                first_group,
                roots: parts.instances.len(),
                end: (nodes, blocks),
                unbounded: parts.unbounded.len(),
                top: parts.top,
            });
        };
        let (roots, unbounded) = (g.first_member as usize, g.first_unbounded as usize);
        if roots > parts.instances.len() || unbounded > parts.unbounded.len() {
            return Err(bad);
        }
        let end = (g.first_node, g.first_block);
        let root = SceneTree {
            nodes: end.0,
            blocks: end.1,
            ..<SceneTree as bytemuck::Zeroable>::zeroed()
        };
        let top = sub_tree(&parts.top, &root, InstanceBox::WORDS).ok_or(bad)?;
        Ok(Self {
            first_group,
            roots,
            end,
            unbounded,
            top,
        })
    }

    /// The error of a world's share that does not add up.
    fn bad(&self) -> SceneError {
        SceneError::BadGroup {
            tree: self.first_group.unwrap_or(0),
        }
    }

    /// The world's level: its instances (any tree, paths counted as in a group), its top tree
    /// and its unbounded entries.
    fn level(&self, parts: &SceneParts<'a>) -> Result<Level<'a>, SceneError> {
        let instances = &parts.instances[..self.roots];
        let mut paths = 0u32;
        for (k, inst) in instances.iter().enumerate() {
            let tree = parts
                .trees
                .get(inst.tree as usize)
                .ok_or(SceneError::BadInstance { inst: k })?;
            if inst.path != paths {
                return Err(SceneError::BadInstance { inst: k });
            }
            paths = paths.checked_add(tree.paths).ok_or(SceneError::TooMany)?;
        }
        let t = &self.top;
        let top = Bvh8Ref::<InstanceBox>::new(t.nodes, t.blocks, t.ids, self.roots)
            .map_err(SceneError::Top)?;
        check_parts(parts, top, instances, None)?;
        let unbounded = &parts.unbounded[..self.unbounded];
        if let Some(at) = unbounded.iter().position(|&i| i as usize >= self.roots) {
            return Err(SceneError::BadUnbounded { at });
        }
        Ok(Level {
            top,
            first: 0,
            instances,
            unbounded,
            slack: origin_slack(instances, parts.trees),
            mask: u32::MAX,
        })
    }
}

/// Checks tree `i`: its slices follow the previous tree's of its kind and make a valid tree,
/// then its members (a geometry tree) or its instances (a group).
fn check_tree<T: Primitive, S: Primitive>(
    parts: &SceneParts<'_>,
    i: usize,
    at: &mut Cursor,
) -> Result<(), SceneError> {
    let g = &parts.trees[i];
    let (tree, words) = match g.kind {
        TRIANGLES => (&parts.triangles, T::WORDS),
        SPHERES => (&parts.spheres, S::WORDS),
        INSTANCES => (&parts.top, InstanceBox::WORDS),
        _ => return Err(SceneError::BadKind { at: i }),
    };
    let next = &mut at.next[g.kind as usize];
    let bad_range = SceneError::BadRange { tree: i };
    if (g.first_node, g.first_block) != *next {
        return Err(bad_range);
    }
    let sub = sub_tree(tree, g, words).ok_or(bad_range)?;
    let err = |error| SceneError::Tree { tree: i, error };
    let prims = g.prims as usize;
    match g.kind {
        TRIANGLES => Bvh8Ref::<T>::new(sub.nodes, sub.blocks, sub.ids, prims).map(drop),
        SPHERES => Bvh8Ref::<S>::new(sub.nodes, sub.blocks, sub.ids, prims).map(drop),
        _ => Bvh8Ref::<InstanceBox>::new(sub.nodes, sub.blocks, sub.ids, prims).map(drop),
    }
    .map_err(err)?;
    if g.kind == INSTANCES {
        // Checked above; its instances' range is checked with the group.
        let top = Bvh8Ref::<InstanceBox>::trusted(sub.nodes, sub.blocks, sub.ids, g.prims);
        let first = g.first_member as usize;
        let bad = SceneError::BadGroup { tree: i };
        let instances = first
            .checked_add(prims)
            .and_then(|end| parts.instances.get(first..end))
            .ok_or(bad)?;
        check_parts(parts, top, instances, Some(i))?;
    }
    *next = g
        .first_node
        .checked_add(g.nodes)
        .zip(g.first_block.checked_add(g.blocks))
        .ok_or(bad_range)?;
    if g.kind == INSTANCES {
        check_group(parts, i, &mut at.inst, &mut at.unbounded)
    } else {
        check_members(parts, i, &mut at.member)
    }
}

/// Checks each part in a level's tree `top` over `instances`: its node is one of its instance's
/// tree (a group's instance: the root), so that a walk entering the part walks a subtree of
/// that tree. Instances naming no tree are left to the instance checks.
fn check_parts(
    parts: &SceneParts<'_>,
    top: Bvh8Ref<'_, InstanceBox>,
    instances: &[crate::scene::Instance],
    level: Option<usize>,
) -> Result<(), SceneError> {
    for (slot, &id) in top.ids().iter().enumerate() {
        if id == crate::bvh::PAD {
            continue;
        }
        let node = super::part_node(&top, slot);
        let tree = instances
            .get(id as usize)
            .and_then(|i| parts.trees.get(i.tree as usize));
        let ok = match tree {
            Some(t) if t.kind != INSTANCES => node == 0 || node < t.nodes,
            _ => node == 0,
        };
        if !ok {
            return Err(SceneError::BadPart { level, slot });
        }
    }
    Ok(())
}

/// Checks geometry tree `i`'s members: the next ones in the list, geometries of its kind in
/// increasing order, their primitives one after another adding up to the tree's, their masks
/// ANDed to its mask.
fn check_members(
    parts: &SceneParts<'_>,
    i: usize,
    next_member: &mut usize,
) -> Result<(), SceneError> {
    let g = &parts.trees[i];
    let bad = SceneError::BadMembers { tree: i };
    if (g.levels, g.paths, g.first_unbounded, g.unbounded) != (0, 1, 0, 0)
        || g.slack.to_bits() != SLACK.to_bits()
    {
        return Err(bad);
    }
    let members = (g.first_member as usize == *next_member)
        .then(|| {
            parts
                .members
                .get(*next_member..next_member.checked_add(g.members as usize)?)
        })
        .flatten()
        .filter(|m| !m.is_empty())
        .ok_or(bad)?;
    *next_member += members.len();
    let mut sum = 0u64;
    let mut last = None;
    let mut mask = u32::MAX;
    for m in members {
        let geo = parts.geometries.get(m.geom as usize).ok_or(bad)?;
        if geo.kind != g.kind || u64::from(m.first_prim) != sum || last >= Some(m.geom) {
            return Err(bad);
        }
        last = Some(m.geom);
        sum += u64::from(geo.prims);
        mask &= geo.mask;
    }
    if sum != u64::from(g.prims) || mask != g.mask {
        return Err(bad);
    }
    Ok(())
}

/// Every slice was read to its end by the trees (the world's top slices too, when there is no
/// group), every member and every instance and unbounded entry.
fn check_all_read<T: Primitive, S: Primitive>(
    parts: &SceneParts<'_>,
    at: &Cursor,
    world: &World<'_>,
) -> Result<(), SceneError> {
    // Without groups the world's tree is the whole top slices.
    let kinds = if world.first_group.is_some() { 3 } else { 2 };
    for (kind, tree, words) in [
        (TRIANGLES, &parts.triangles, T::WORDS),
        (SPHERES, &parts.spheres, S::WORDS),
        (INSTANCES, &parts.top, InstanceBox::WORDS),
    ]
    .into_iter()
    .take(kinds)
    {
        let (n, b) = at.next[kind as usize];
        if n as usize != tree.nodes.len()
            || Some(tree.ids.len()) != (b as usize).checked_mul(BLOCK)
            || Some(tree.blocks.len()) != (b as usize).checked_mul(words)
        {
            return Err(SceneError::Unused { kind });
        }
    }
    if at.member != parts.members.len() {
        return Err(SceneError::Unused { kind: 3 });
    }
    if at.inst != parts.instances.len() || at.unbounded != parts.unbounded.len() {
        return Err(world.bad());
    }
    Ok(())
}

/// Checks group `i` (its tree already checked): its instances follow `next_inst` and place
/// trees before it, their paths count up from 0, its levels, paths, mask and slack are what
/// they make them, its unbounded entries follow `next_unbounded` and name its instances.
fn check_group(
    parts: &SceneParts<'_>,
    i: usize,
    next_inst: &mut usize,
    next_unbounded: &mut usize,
) -> Result<(), SceneError> {
    let g = &parts.trees[i];
    let bad = SceneError::BadGroup { tree: i };
    let first = g.first_member as usize;
    let end = first.checked_add(g.members as usize).ok_or(bad)?;
    if first != *next_inst || g.members != g.prims {
        return Err(bad);
    }
    let instances = parts.instances.get(first..end).ok_or(bad)?;
    let u0 = g.first_unbounded as usize;
    let u1 = u0.checked_add(g.unbounded as usize).ok_or(bad)?;
    if u0 != *next_unbounded
        || !parts
            .unbounded
            .get(u0..u1)
            .ok_or(bad)?
            .iter()
            .all(|&k| (first..end).contains(&(k as usize)))
    {
        return Err(bad);
    }
    let (mut paths, mut levels, mut mask) = (0u32, 0u32, 0u32);
    for (k, inst) in instances.iter().enumerate() {
        let bad_inst = SceneError::BadInstance { inst: first + k };
        // Trees before the group were checked before it: their fields can be trusted here.
        let child = parts
            .trees
            .get(inst.tree as usize)
            .filter(|_| (inst.tree as usize) < i)
            .ok_or(bad_inst)?;
        if inst.path != paths {
            return Err(bad_inst);
        }
        paths = paths.checked_add(child.paths).ok_or(SceneError::TooMany)?;
        levels = levels.max(child.levels);
        mask |= inst.mask;
    }
    let slack = origin_slack(instances, parts.trees);
    if g.paths != paths
        || g.levels != levels + 1
        || g.levels >= MAX_INSTANCE_LEVELS
        || g.mask != mask
        || g.slack.to_bits() != slack.to_bits()
    {
        return Err(bad);
    }
    *next_inst = end;
    *next_unbounded = u1;
    Ok(())
}
