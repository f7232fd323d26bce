"""The C ABI job (capi/examples/digest.rs: a terrain placed nine times, one mirrored, and four
spheres; camera rays, shadow rays, every hit along the camera rays, closest points) built and
traced from Python: the digest of the Python answers equals the Rust API's, at every tier."""

import os
import re
import subprocess

import numpy as np
import pytest

import octoray

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
GRID, WIDTH, HEIGHT = 24, 64, 48
F = np.float32


def rust_answers(tier):
    """What `capi/examples/digest.rs` prints for `tier` (built here when missing): the counts of
    hits, rays in shadow and hits along, and the digest."""
    # The command `.ci/capi.sh` builds the examples with: nothing to do after it in CI.
    subprocess.run(
        ["cargo", "build", "--quiet", "--profile", "test", "--workspace", "--lib", "--examples"],
        cwd=ROOT,
        check=True,
    )
    exe = os.path.join(ROOT, "target", "debug", "examples", "digest")
    line = subprocess.run([exe, str(tier)], capture_output=True, check=True, text=True).stdout
    m = re.search(r"(\d+) hit, (\d+) in shadow, (\d+) hits along them.*digest 0x([0-9a-f]{16})", line)
    return int(m.group(1)), int(m.group(2)), int(m.group(3)), int(m.group(4), 16)


def fnv(words):
    """FNV-1a over the little-endian bytes of 32-bit words (the library's `Digest`)."""
    h = 0xCBF29CE484222325
    for b in np.asarray(words, dtype="<u4").tobytes():
        h = ((h ^ b) * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return h


def bits(a):
    return np.asarray(a, dtype=F).view(np.uint32)


def ids(a):
    return np.asarray(a, dtype=np.int64).astype(np.uint32)


def job_scene(tier):
    x, z = np.meshgrid(np.arange(GRID + 1), np.arange(GRID + 1), indexing="xy")
    verts = np.c_[x.ravel(), ((x * 7 + z * 13) % 5).ravel() * 0.25, z.ravel()].astype(F)
    at = lambda x, z: z * (GRID + 1) + x  # noqa: E731
    faces = []
    for zz in range(GRID):
        for xx in range(GRID):
            a, b, c, d = at(xx, zz), at(xx + 1, zz), at(xx + 1, zz + 1), at(xx, zz + 1)
            faces += [(a, b, c), (a, c, d)]
    s = octoray.Scene(tier)
    terrain = s.add_mesh(verts, np.array(faces))
    balls = s.add_spheres([((k * 9 - 12), 6, 10) for k in range(4)], [2.0 + 0.5 * k for k in range(4)])
    for i in range(9):
        sc = 1.0 if i % 2 == 0 else 0.5
        mirror = -1.0 if i == 4 else 1.0
        m = np.diag([mirror * sc, sc, sc, 1.0])
        m[:3, 3] = ((i % 3) * 30 - 45, -2, (i // 3) * 30 - 20)
        s.add_instance(terrain, m, mask=1)
    s.add_instance(balls, mask=2)
    return s


def placed_words(t, u, v, prim, geom, inst):
    return np.c_[bits(t), bits(u), bits(v), ids(prim), ids(geom), ids(inst)].ravel()


@pytest.mark.parametrize("tier", [0, 1, 2])
def test_python_digest_equals_the_rust_apis(tier):
    s = job_scene(octoray.TIERS[[2, 0, 1][tier]])
    k = np.arange(WIDTH * HEIGHT)
    dx = ((k % WIDTH).astype(F) + F(0.5)) / F(32) - F(1)
    dy = ((k // WIDTH).astype(F) + F(0.5)) / F(24) - F(1)
    dirs = np.c_[dx, F(-0.35) - F(0.3) * dy, np.ones_like(dx)].astype(F)
    origins = np.broadcast_to(np.array([0, 25, -60], dtype=F), dirs.shape)
    rays = np.hstack([origins, dirs])
    h = s.closest(rays)
    # Shadow rays from each hit point towards the light, t in [1e-3, 1].
    p = (origins + dirs * h.t[:, None])[h.hit]
    light = np.array([20, 60, -10], dtype=F)
    blocked = s.occluded(np.hstack([p, light - p]), t_min=F(1e-3), t_max=1.0)
    along = s.all_hits(rays)
    near = s.closest_points(p + np.array([0, 1.5, 0], dtype=F))
    keep = slice(0, len(rays) * 8)
    words = np.concatenate(
        [
            placed_words(h.t, h.u, h.v, h.prim, h.geom, h.inst),
            blocked.astype(np.uint32),
            placed_words(*(getattr(along, f)[keep] for f in ("t", "u", "v", "prim", "geom", "inst"))),
            np.c_[
                bits(near.point),
                bits(near.distance),
                bits(near.u),
                bits(near.v),
                ids(near.prim),
                ids(near.geom),
                ids(near.inst),
            ].ravel(),
        ]
    )
    hit, shadow, hits_along, digest = rust_answers(tier)
    assert (h.hit.sum(), blocked.sum(), len(along.ray)) == (hit, shadow, hits_along)
    assert hit > 500 and shadow > 0 and hits_along > hit
    assert fnv(words) == digest
