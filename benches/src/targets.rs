//! The scene report's speed targets: what each compares, octoray's row against a peer's, and the
//! ratio it asks for. The scene report (`--bin scenes`) prints each target's measured ratio; the
//! counts report (`--bin profile -- --report`) counts both rows of every target missed.

/// One target: octoray's row ≥ `ratio` × the peer's row (Mrays/s, one thread).
pub struct Target {
    /// What the target asks, as the reports print it.
    pub what: &'static str,
    /// Octoray's row: `rays|query|traversal|tier` as the scene report keys its rows.
    pub octoray: &'static str,
    /// The peer's row, keyed the same way.
    pub peer: &'static str,
    /// The ratio asked for.
    pub ratio: f64,
}

/// Every target, in the order the reports print them.
pub const TARGETS: &[Target] = &[
    Target {
        what: "primary packet-8 ≥ 1.2× Embree robust rtcIntersect8",
        octoray: "primary|closest|packet-8 (4×2 tiles)|watertight",
        peer: "primary|closest|packet-8 (rtcIntersect8)|Embree 3 robust",
        ratio: 1.2,
    },
    Target {
        what: "primary single ray ≥ 1.2× Embree robust rtcIntersect1",
        octoray: "primary|closest|single ray (leaves ×8)|watertight",
        peer: "primary|closest|single ray (rtcIntersect1)|Embree 3 robust",
        ratio: 1.2,
    },
    Target {
        what: "diffuse bounce ≥ 1.2× Embree robust rtcIntersect1",
        octoray: "diffuse bounce|closest|single ray|watertight",
        peer: "diffuse bounce|closest|single ray (rtcIntersect1)|Embree 3 robust",
        ratio: 1.2,
    },
    Target {
        what: "primary single ray ≥ tinybvh BVH8_CPU (BuildHQ)",
        octoray: "primary|closest|single ray (leaves ×8)|watertight",
        peer: "primary|closest|single ray|tinybvh 1.6.8 (BVH8_CPU, BuildHQ: spatial splits)",
        ratio: 1.0,
    },
    Target {
        what: "primary single ray, standard tier ≥ 1.2× tinybvh BVH8_CPU (BuildHQ)",
        octoray: "primary|closest|single ray|standard",
        peer: "primary|closest|single ray|tinybvh 1.6.8 (BVH8_CPU, BuildHQ: spatial splits)",
        ratio: 1.2,
    },
    Target {
        what: "diffuse bounce ≥ tinybvh BVH8_CPU (BuildHQ)",
        octoray: "diffuse bounce|closest|single ray|watertight",
        peer: "diffuse bounce|closest|single ray|tinybvh 1.6.8 (BVH8_CPU, BuildHQ: spatial splits)",
        ratio: 1.0,
    },
    Target {
        what: "primary packet-8 ≥ 1.2× Embree robust rtcIntersect8, spatial splits",
        octoray: "primary|closest|packet-8 (4×2 tiles)|watertight, spatial splits",
        peer: "primary|closest|packet-8 (rtcIntersect8)|Embree 3 robust",
        ratio: 1.2,
    },
    Target {
        what: "primary single ray ≥ 1.2× Embree robust rtcIntersect1, spatial splits",
        octoray: "primary|closest|single ray (leaves ×8)|watertight, spatial splits",
        peer: "primary|closest|single ray (rtcIntersect1)|Embree 3 robust",
        ratio: 1.2,
    },
    Target {
        what: "diffuse bounce ≥ 1.2× Embree robust rtcIntersect1, spatial splits",
        octoray: "diffuse bounce|closest|single ray|watertight, spatial splits",
        peer: "diffuse bounce|closest|single ray (rtcIntersect1)|Embree 3 robust",
        ratio: 1.2,
    },
    Target {
        what: "primary single ray ≥ tinybvh BVH8_CPU (BuildHQ), spatial splits",
        octoray: "primary|closest|single ray (leaves ×8)|watertight, spatial splits",
        peer: "primary|closest|single ray|tinybvh 1.6.8 (BVH8_CPU, BuildHQ: spatial splits)",
        ratio: 1.0,
    },
    Target {
        what: "diffuse bounce ≥ tinybvh BVH8_CPU (BuildHQ), spatial splits",
        octoray: "diffuse bounce|closest|single ray|watertight, spatial splits",
        peer: "diffuse bounce|closest|single ray|tinybvh 1.6.8 (BVH8_CPU, BuildHQ: spatial splits)",
        ratio: 1.0,
    },
    Target {
        what: "camera 2 single ray ≥ 1.2× Embree robust rtcIntersect1",
        octoray: "primary (camera 2)|closest|single ray|watertight",
        peer: "primary (camera 2)|closest|single ray (rtcIntersect1)|Embree 3 robust",
        ratio: 1.2,
    },
    Target {
        what: "camera 2 packet-8 ≥ 1.2× Embree robust rtcIntersect8",
        octoray: "primary (camera 2)|closest|packet-8 (4×2 tiles)|watertight",
        peer: "primary (camera 2)|closest|packet-8 (rtcIntersect8)|Embree 3 robust",
        ratio: 1.2,
    },
    Target {
        what: "shadow single ray ≥ 1.2× Embree robust rtcOccluded1",
        octoray: "shadow|any|single ray|watertight",
        peer: "shadow|any|single ray (rtcOccluded1)|Embree 3 robust",
        ratio: 1.2,
    },
    Target {
        what: "camera 2 single ray ≥ tinybvh BVH8_CPU (BuildHQ)",
        octoray: "primary (camera 2)|closest|single ray|watertight",
        peer: "primary (camera 2)|closest|single ray|tinybvh 1.6.8 (BVH8_CPU, BuildHQ: spatial splits)",
        ratio: 1.0,
    },
    Target {
        what: "camera 2 single ray ≥ 1.2× Embree robust rtcIntersect1, spatial splits",
        octoray: "primary (camera 2)|closest|single ray|watertight, spatial splits",
        peer: "primary (camera 2)|closest|single ray (rtcIntersect1)|Embree 3 robust",
        ratio: 1.2,
    },
    Target {
        what: "shadow single ray ≥ 1.2× Embree robust rtcOccluded1, spatial splits",
        octoray: "shadow|any|single ray|watertight, spatial splits",
        peer: "shadow|any|single ray (rtcOccluded1)|Embree 3 robust",
        ratio: 1.2,
    },
    Target {
        what: "camera 2 single ray ≥ tinybvh BVH8_CPU (BuildHQ), spatial splits",
        octoray: "primary (camera 2)|closest|single ray|watertight, spatial splits",
        peer: "primary (camera 2)|closest|single ray|tinybvh 1.6.8 (BVH8_CPU, BuildHQ: spatial splits)",
        ratio: 1.0,
    },
    Target {
        what: "primary single ray ≥ 2× obvhs",
        octoray: "primary|closest|single ray (leaves ×8)|watertight",
        peer: "primary|closest|single ray|obvhs 0.4 (CWBVH)",
        ratio: 2.0,
    },
    Target {
        what: "primary any hit ≥ 2× obvhs",
        octoray: "primary|any|single ray|watertight",
        peer: "primary|any|single ray|obvhs 0.4 (CWBVH)",
        ratio: 2.0,
    },
    Target {
        what: "diffuse bounce ≥ 2× obvhs",
        octoray: "diffuse bounce|closest|single ray|watertight",
        peer: "diffuse bounce|closest|single ray|obvhs 0.4 (CWBVH)",
        ratio: 2.0,
    },
    Target {
        what: "shadow single ray ≥ 2× obvhs",
        octoray: "shadow|any|single ray|watertight",
        peer: "shadow|any|single ray|obvhs 0.4 (CWBVH)",
        ratio: 2.0,
    },
];
