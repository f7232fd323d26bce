//! The scene report's speed targets: what each compares, octoray's row against a peer's, and the
//! ratio it asks for. The scene report (`--bin scenes`) prints each target's measured ratio; the
//! counts report (`--bin profile -- --report`) counts both rows of every target missed.

use crate::scene::row::Query::{Any, Closest};
use crate::scene::row::RaySet::{Bounce, Camera2, Primary, Shadow};
use crate::scene::row::Traversal::{Packet8, Single};
use crate::scene::row::{Row, System, Tier};

const WATERTIGHT: System = System::Octoray(Tier::Watertight);
const SPATIAL: System = System::Octoray(Tier::Spatial);
const STANDARD: System = System::Octoray(Tier::Standard);
const EMBREE: System = System::Embree { robust: true };
const TINYBVH: System = System::TinyBvh { hq: true };
const OBVHS: System = System::Obvhs;

/// One target: octoray's row ≥ `ratio` × the peer's row (Mrays/s, one thread).
pub struct Target {
    /// What the target asks, as the reports print it.
    pub what: &'static str,
    /// Octoray's row.
    pub octoray: Row,
    /// The peer's row.
    pub peer: Row,
    /// The ratio asked for.
    pub ratio: f64,
}

/// Every target, in the order the reports print them.
pub const TARGETS: &[Target] = &[
    Target {
        what: "primary packet-8 ≥ 1.2× Embree robust rtcIntersect8",
        octoray: Row::new(Primary, Closest, Packet8, WATERTIGHT),
        peer: Row::new(Primary, Closest, Packet8, EMBREE),
        ratio: 1.2,
    },
    Target {
        what: "primary single ray ≥ 1.2× Embree robust rtcIntersect1",
        octoray: Row::new(Primary, Closest, Single, WATERTIGHT),
        peer: Row::new(Primary, Closest, Single, EMBREE),
        ratio: 1.2,
    },
    Target {
        what: "diffuse bounce ≥ 1.2× Embree robust rtcIntersect1",
        octoray: Row::new(Bounce, Closest, Single, WATERTIGHT),
        peer: Row::new(Bounce, Closest, Single, EMBREE),
        ratio: 1.2,
    },
    Target {
        what: "primary single ray ≥ tinybvh BVH8_CPU (BuildHQ)",
        octoray: Row::new(Primary, Closest, Single, WATERTIGHT),
        peer: Row::new(Primary, Closest, Single, TINYBVH),
        ratio: 1.0,
    },
    Target {
        what: "primary single ray, standard tier ≥ 1.2× tinybvh BVH8_CPU (BuildHQ)",
        octoray: Row::new(Primary, Closest, Single, STANDARD),
        peer: Row::new(Primary, Closest, Single, TINYBVH),
        ratio: 1.2,
    },
    Target {
        what: "diffuse bounce ≥ tinybvh BVH8_CPU (BuildHQ)",
        octoray: Row::new(Bounce, Closest, Single, WATERTIGHT),
        peer: Row::new(Bounce, Closest, Single, TINYBVH),
        ratio: 1.0,
    },
    Target {
        what: "primary packet-8 ≥ 1.2× Embree robust rtcIntersect8, spatial splits",
        octoray: Row::new(Primary, Closest, Packet8, SPATIAL),
        peer: Row::new(Primary, Closest, Packet8, EMBREE),
        ratio: 1.2,
    },
    Target {
        what: "primary single ray ≥ 1.2× Embree robust rtcIntersect1, spatial splits",
        octoray: Row::new(Primary, Closest, Single, SPATIAL),
        peer: Row::new(Primary, Closest, Single, EMBREE),
        ratio: 1.2,
    },
    Target {
        what: "diffuse bounce ≥ 1.2× Embree robust rtcIntersect1, spatial splits",
        octoray: Row::new(Bounce, Closest, Single, SPATIAL),
        peer: Row::new(Bounce, Closest, Single, EMBREE),
        ratio: 1.2,
    },
    Target {
        what: "primary single ray ≥ tinybvh BVH8_CPU (BuildHQ), spatial splits",
        octoray: Row::new(Primary, Closest, Single, SPATIAL),
        peer: Row::new(Primary, Closest, Single, TINYBVH),
        ratio: 1.0,
    },
    Target {
        what: "diffuse bounce ≥ tinybvh BVH8_CPU (BuildHQ), spatial splits",
        octoray: Row::new(Bounce, Closest, Single, SPATIAL),
        peer: Row::new(Bounce, Closest, Single, TINYBVH),
        ratio: 1.0,
    },
    Target {
        what: "camera 2 single ray ≥ 1.2× Embree robust rtcIntersect1",
        octoray: Row::new(Camera2, Closest, Single, WATERTIGHT),
        peer: Row::new(Camera2, Closest, Single, EMBREE),
        ratio: 1.2,
    },
    Target {
        what: "camera 2 packet-8 ≥ 1.2× Embree robust rtcIntersect8",
        octoray: Row::new(Camera2, Closest, Packet8, WATERTIGHT),
        peer: Row::new(Camera2, Closest, Packet8, EMBREE),
        ratio: 1.2,
    },
    Target {
        what: "shadow single ray ≥ 1.2× Embree robust rtcOccluded1",
        octoray: Row::new(Shadow, Any, Single, WATERTIGHT),
        peer: Row::new(Shadow, Any, Single, EMBREE),
        ratio: 1.2,
    },
    Target {
        what: "camera 2 single ray ≥ tinybvh BVH8_CPU (BuildHQ)",
        octoray: Row::new(Camera2, Closest, Single, WATERTIGHT),
        peer: Row::new(Camera2, Closest, Single, TINYBVH),
        ratio: 1.0,
    },
    Target {
        what: "camera 2 single ray ≥ 1.2× Embree robust rtcIntersect1, spatial splits",
        octoray: Row::new(Camera2, Closest, Single, SPATIAL),
        peer: Row::new(Camera2, Closest, Single, EMBREE),
        ratio: 1.2,
    },
    Target {
        what: "shadow single ray ≥ 1.2× Embree robust rtcOccluded1, spatial splits",
        octoray: Row::new(Shadow, Any, Single, SPATIAL),
        peer: Row::new(Shadow, Any, Single, EMBREE),
        ratio: 1.2,
    },
    Target {
        what: "camera 2 single ray ≥ tinybvh BVH8_CPU (BuildHQ), spatial splits",
        octoray: Row::new(Camera2, Closest, Single, SPATIAL),
        peer: Row::new(Camera2, Closest, Single, TINYBVH),
        ratio: 1.0,
    },
    Target {
        what: "primary single ray ≥ 2× obvhs",
        octoray: Row::new(Primary, Closest, Single, WATERTIGHT),
        peer: Row::new(Primary, Closest, Single, OBVHS),
        ratio: 2.0,
    },
    Target {
        what: "primary any hit ≥ 2× obvhs",
        octoray: Row::new(Primary, Any, Single, WATERTIGHT),
        peer: Row::new(Primary, Any, Single, OBVHS),
        ratio: 2.0,
    },
    Target {
        what: "diffuse bounce ≥ 2× obvhs",
        octoray: Row::new(Bounce, Closest, Single, WATERTIGHT),
        peer: Row::new(Bounce, Closest, Single, OBVHS),
        ratio: 2.0,
    },
    Target {
        what: "shadow single ray ≥ 2× obvhs",
        octoray: Row::new(Shadow, Any, Single, WATERTIGHT),
        peer: Row::new(Shadow, Any, Single, OBVHS),
        ratio: 2.0,
    },
];
