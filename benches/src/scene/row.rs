//! A row of the scene report as a type: which rays, which query, how they are traversed, and
//! which system traces them. Targets, the chart and the counts report name rows by this key;
//! the labels the report prints are derived from it, so relabelling a row cannot unlink it.

/// The ray sets of a scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RaySet {
    /// Primary rays of the first camera, in 4×2 (packet-8) or 4×4 (packet-16) pixel tiles.
    Primary,
    /// Primary rays of the second camera, in 4×2 tiles.
    Camera2,
    /// Cosine-distributed bounces from the first camera's hits.
    Bounce,
    /// Rays from the first camera's hits to the light.
    Shadow,
}

/// What a row asks of each ray.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Query {
    /// The closest hit.
    Closest,
    /// Whether anything is hit (occlusion).
    Any,
}

/// How a row hands its rays to the system.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Traversal {
    /// Packets of 8 rays.
    Packet8,
    /// Packets of 16 rays.
    Packet16,
    /// One ray at a time.
    Single,
    /// The batch call, which picks packets or single rays per 8 rays.
    Batch,
}

/// An octoray tree and tier the report traces.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Tier {
    /// The watertight tier on the binned-SAH tree.
    Watertight,
    /// The watertight tier on the tree with spatial splits.
    Spatial,
    /// The standard (Möller–Trumbore) tier on the binned-SAH tree.
    Standard,
}

/// A system that traces a row.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum System {
    /// octoray.
    Octoray(Tier),
    /// obvhs's CWBVH.
    Obvhs,
    /// The `bvh` crate.
    Bvh,
    /// tinybvh's `BVH8_CPU`: `BuildHQ` (spatial splits) when `true`, `Build` (binned) otherwise.
    TinyBvh {
        /// `BuildHQ`.
        hq: bool,
    },
    /// Embree 3: robust mode when `true`, fast mode otherwise.
    Embree {
        /// `RTC_SCENE_FLAG_ROBUST`.
        robust: bool,
    },
}

/// One row of the scene report.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Row {
    /// The rays.
    pub rays: RaySet,
    /// The query.
    pub query: Query,
    /// How the rays are handed over.
    pub traversal: Traversal,
    /// Who traces them.
    pub system: System,
}

impl RaySet {
    /// The report's label.
    pub const fn label(self) -> &'static str {
        match self {
            RaySet::Primary => "primary",
            RaySet::Camera2 => "primary (camera 2)",
            RaySet::Bounce => "diffuse bounce",
            RaySet::Shadow => "shadow",
        }
    }
}

impl System {
    /// The report's label.
    pub const fn label(self) -> &'static str {
        match self {
            System::Octoray(Tier::Watertight) => "watertight",
            System::Octoray(Tier::Spatial) => "watertight, spatial splits",
            System::Octoray(Tier::Standard) => "standard",
            System::Obvhs => "obvhs 0.4 (CWBVH)",
            System::Bvh => "bvh 0.13",
            System::TinyBvh { hq: true } => "tinybvh 1.6.8 (BVH8_CPU, BuildHQ: spatial splits)",
            System::TinyBvh { hq: false } => "tinybvh 1.6.8 (BVH8_CPU, Build: binned)",
            System::Embree { robust: true } => "Embree 3 robust",
            System::Embree { robust: false } => "Embree 3 fast",
        }
    }

    /// Whether the system has an occlusion query (tinybvh's wrapper has none: its
    /// [`Query::Any`] rows time the closest hit within the segment).
    pub const fn has_occlusion(self) -> bool {
        !matches!(self, System::TinyBvh { .. })
    }

    /// The rows the report times for this system, in order: ray set, query, traversal.
    pub fn rows(self) -> &'static [(RaySet, Query, Traversal)] {
        use Query::{Any, Closest};
        use RaySet::{Bounce, Camera2, Primary, Shadow};
        use Traversal::{Batch, Packet16, Packet8, Single};
        match self {
            System::Octoray(Tier::Watertight) => &[
                (Primary, Closest, Packet8),
                (Primary, Closest, Packet16),
                (Primary, Closest, Single),
                (Primary, Any, Packet8),
                (Primary, Any, Single),
                (Bounce, Closest, Single),
                (Bounce, Closest, Batch),
                (Bounce, Any, Single),
                (Camera2, Closest, Packet8),
                (Camera2, Closest, Single),
                (Shadow, Any, Packet8),
                (Shadow, Any, Single),
            ],
            System::Octoray(Tier::Standard) => &[
                (Primary, Closest, Packet8),
                (Primary, Closest, Single),
                (Camera2, Closest, Single),
            ],
            System::Octoray(Tier::Spatial) => &[
                (Primary, Closest, Packet8),
                (Primary, Closest, Single),
                (Primary, Any, Single),
                (Bounce, Closest, Single),
                (Camera2, Closest, Single),
                (Shadow, Any, Single),
            ],
            System::Obvhs => &[
                (Primary, Closest, Single),
                (Primary, Any, Single),
                (Bounce, Closest, Single),
                (Camera2, Closest, Single),
                (Shadow, Any, Single),
            ],
            System::Bvh => &[(Primary, Closest, Single)],
            System::TinyBvh { .. } => &[
                (Primary, Closest, Single),
                (Bounce, Closest, Single),
                (Camera2, Closest, Single),
                (Shadow, Any, Single),
            ],
            System::Embree { .. } => &[
                (Primary, Closest, Packet8),
                (Primary, Closest, Single),
                (Primary, Any, Packet8),
                (Primary, Any, Single),
                (Bounce, Closest, Single),
                (Camera2, Closest, Packet8),
                (Camera2, Closest, Single),
                (Shadow, Any, Packet8),
                (Shadow, Any, Single),
            ],
        }
    }
}

impl Row {
    /// The row of `system` for `rays`, `query` and `traversal`.
    pub const fn new(rays: RaySet, query: Query, traversal: Traversal, system: System) -> Self {
        Self {
            rays,
            query,
            traversal,
            system,
        }
    }

    /// The report's four label cells: rays, query, traversal, tier or peer.
    pub const fn cells(self) -> [&'static str; 4] {
        [
            self.rays.label(),
            self.query_label(),
            self.traversal_label(),
            self.system.label(),
        ]
    }

    /// The query as the report names it for this system.
    const fn query_label(self) -> &'static str {
        match self.query {
            Query::Closest => "closest",
            Query::Any if self.system.has_occlusion() => "any",
            Query::Any => "closest (no occlusion query)",
        }
    }

    /// The traversal as the report names it: Embree's rows name the call.
    const fn traversal_label(self) -> &'static str {
        let embree = matches!(self.system, System::Embree { .. });
        match (self.traversal, self.query, embree) {
            (Traversal::Packet8, Query::Closest, true) => "packet-8 (rtcIntersect8)",
            (Traversal::Packet8, Query::Any, true) => "packet-8 (rtcOccluded8)",
            (Traversal::Single, Query::Closest, true) => "single ray (rtcIntersect1)",
            (Traversal::Single, Query::Any, true) => "single ray (rtcOccluded1)",
            (Traversal::Packet8, _, _) => "packet-8",
            (Traversal::Packet16, _, _) => "packet-16",
            (Traversal::Single, _, _) => "single ray",
            (Traversal::Batch, _, _) => "batch (picks per 8 rays)",
        }
    }
}

impl std::fmt::Display for Row {
    /// The label cells joined by ", ".
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.cells().join(", "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_system_row_has_its_own_labels() {
        let systems = [
            System::Octoray(Tier::Watertight),
            System::Octoray(Tier::Spatial),
            System::Octoray(Tier::Standard),
            System::Obvhs,
            System::Bvh,
            System::TinyBvh { hq: true },
            System::TinyBvh { hq: false },
            System::Embree { robust: true },
            System::Embree { robust: false },
        ];
        let mut seen = std::collections::HashSet::new();
        for s in systems {
            for &(r, q, t) in s.rows() {
                let row = Row::new(r, q, t, s);
                assert!(seen.insert(row.cells()), "two rows print as {row}");
            }
        }
        assert_eq!(
            Row::new(
                RaySet::Shadow,
                Query::Any,
                Traversal::Single,
                System::Embree { robust: true }
            )
            .to_string(),
            "shadow, any, single ray (rtcOccluded1), Embree 3 robust"
        );
        assert_eq!(
            Row::new(
                RaySet::Shadow,
                Query::Any,
                Traversal::Single,
                System::TinyBvh { hq: true }
            )
            .cells()[1],
            "closest (no occlusion query)"
        );
    }
}
