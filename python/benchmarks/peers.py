"""First hit and occlusion from Python: octoray against embreex (Embree 4, through trimesh's ray
interface) and Open3D's RaycastingScene (Embree 3), on the same meshes and rays, one thread and
all threads, timed in alternation (best of the rounds). Writes a markdown report.

    python python/benchmarks/peers.py [--rounds 3] [--out benches/python.md]

Meshes: Sponza (the `bvh` crate's media/sponza.obj, found through `cargo metadata`), a
subdivided icosphere and a height-field terrain. Rays: a pinhole camera's primary rays
(coherent) and rays from random points inside the mesh's box in random directions (incoherent).
A system that is not installed is left out of the report, which says so.
"""

import argparse
import json
import os
import platform
import subprocess
import time

import numpy as np
import trimesh

import octoray

WIDTH, HEIGHT = 512, 384


def sponza():
    meta = json.loads(
        subprocess.run(
            ["cargo", "metadata", "--format-version", "1"],
            capture_output=True,
            check=True,
            text=True,
            cwd=os.path.dirname(os.path.abspath(__file__)) + "/../..",
        ).stdout
    )
    for p in meta["packages"]:
        if p["name"] == "bvh":
            path = os.path.join(os.path.dirname(p["manifest_path"]), "media", "sponza.obj")
            if os.path.exists(path):
                return read_obj(path)
    return None


def read_obj(path):
    """Positions and fan-triangulated faces of an OBJ file (materials and textures ignored)."""
    v, f = [], []
    with open(path) as fh:
        for line in fh:
            t = line.split()
            if not t:
                continue
            if t[0] == "v":
                v.append([float(x) for x in t[1:4]])
            elif t[0] == "f":
                idx = [int(x.split("/")[0]) for x in t[1:]]
                idx = [i - 1 if i > 0 else len(v) + i for i in idx]
                f.extend([idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1))
    return np.array(v), np.array(f)


def terrain(n=512):
    x, y = np.meshgrid(np.linspace(-1, 1, n + 1), np.linspace(-1, 1, n + 1))
    rng = np.random.default_rng(1)
    z = 0.1 * np.sin(6 * x) * np.cos(5 * y) + 0.01 * rng.normal(size=x.shape)
    v = np.c_[x.ravel(), y.ravel(), z.ravel()]
    i = np.arange(n * (n + 1)).reshape(n, n + 1)[:, :n].ravel()
    f = np.r_[np.c_[i, i + 1, i + n + 2], np.c_[i, i + n + 2, i + n + 1]]
    return v, f


def meshes():
    out = {}
    s = sponza()
    if s is not None:
        out["Sponza"] = s
    ico = trimesh.creation.icosphere(subdivisions=7)
    out["icosphere"] = (ico.vertices, ico.faces)
    out["terrain"] = terrain()
    return out


def primary(v):
    lo, hi = v.min(0), v.max(0)
    centre, size = (lo + hi) / 2, np.linalg.norm(hi - lo)
    eye = centre + size * np.array([0.35, 0.25, 0.6])
    fwd = centre - eye
    fwd /= np.linalg.norm(fwd)
    right = np.cross(fwd, [0, 1, 0])
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    px, py = np.meshgrid((np.arange(WIDTH) + 0.5) / WIDTH - 0.5, (np.arange(HEIGHT) + 0.5) / HEIGHT - 0.5)
    d = fwd + px.ravel()[:, None] * right * 0.9 + py.ravel()[:, None] * up * 0.9 * HEIGHT / WIDTH
    return np.broadcast_to(eye, d.shape).copy(), d


def incoherent(v, n=WIDTH * HEIGHT):
    rng = np.random.default_rng(3)
    lo, hi = v.min(0), v.max(0)
    return rng.uniform(lo, hi, (n, 3)), rng.normal(size=(n, 3))


def systems(v, f):
    """name -> (first(o, d, threads), any(o, d, threads)), each returning hit face ids / flags."""
    out = {}
    mesh = octoray.Mesh(v, f)
    out["octoray (watertight)"] = (
        lambda o, d, t: mesh.closest(np.hstack([o, d]), threads=t).prim,
        lambda o, d, t: mesh.occluded(np.hstack([o, d]), threads=t),
    )
    try:
        from trimesh.ray.ray_pyembree import RayMeshIntersector

        tm = trimesh.Trimesh(v, f, process=False)
        emb = RayMeshIntersector(tm)
        out["embreex (Embree 4, trimesh)"] = (
            lambda o, d, t: emb.intersects_first(o, d),
            lambda o, d, t: emb.intersects_any(o, d),
        )
    except Exception as e:  # not installed
        print("embreex:", e)
    try:
        import open3d as o3d

        scene = o3d.t.geometry.RaycastingScene()
        scene.add_triangles(o3d.core.Tensor(v.astype(np.float32)), o3d.core.Tensor(f.astype(np.uint32)))

        def valid(ids):
            # Open3D's invalid ID is 2**32 - 1: -1, a miss, as the others report it.
            ids = ids.numpy().astype(np.int64)
            return np.where(ids == 0xFFFFFFFF, -1, ids)

        def rays(o, d):
            return o3d.core.Tensor(np.hstack([o, d]).astype(np.float32))

        out["Open3D (Embree 3)"] = (
            lambda o, d, t: valid(scene.cast_rays(rays(o, d), nthreads=t or 0)["primitive_ids"]),
            lambda o, d, t: scene.test_occlusions(rays(o, d), nthreads=t or 0).numpy(),
        )
    except Exception as e:
        print("open3d:", e)
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    rows = []
    for name, (v, f) in meshes().items():
        v, f = np.asarray(v, np.float64), np.asarray(f, np.int64)
        sys_ = systems(v, f)
        for kind, (o, d) in (("primary", primary(v)), ("incoherent", incoherent(v))):
            for query in (0, 1):
                for threads in (1, None):
                    best = {k: np.inf for k in sys_}
                    hits = {}
                    for _ in range(args.rounds):
                        for k, fns in sys_.items():
                            t0 = time.perf_counter()
                            r = fns[query](o, d, threads)
                            best[k] = min(best[k], time.perf_counter() - t0)
                            hits[k] = int(np.count_nonzero(r >= 0) if query == 0 else np.count_nonzero(r))
                    ours = best["octoray (watertight)"]
                    for k in sys_:
                        rows.append((name, len(f), kind, ["first hit", "occlusion"][query],
                                     "1" if threads == 1 else "all", k,
                                     len(o) / best[k] / 1e6, best[k] / ours, hits[k]))
                    print(rows[-len(sys_):])
    cpu = platform.machine()
    try:
        with open("/proc/cpuinfo") as fh:
            cpu = next(line.split(":", 1)[1].strip() for line in fh if line.startswith("model name"))
        with open("/proc/cpuinfo") as fh:
            flags = fh.read()
        cpu += " (AVX-512)" if "avx512f" in flags else " (AVX2)" if "avx2" in flags else ""
    except (OSError, StopIteration):
        pass
    lines = [
        "# Python ray casting: octoray, embreex, Open3D",
        "",
        f"Written by `python python/benchmarks/peers.py` on {cpu}, {os.cpu_count()} cores, the "
        "wheel built for this CPU (`maturin build --release` inside the repository, whose "
        "`.cargo/config.toml` sets `-C target-cpu=native`); "
        f"best of {args.rounds} alternating rounds; {WIDTH}x{HEIGHT} rays per case; Python "
        "overhead (array conversion, result arrays) included for every system. "
        "embreex traces on the calling thread only (its `all` rows equal its `1`).",
        "",
        "| mesh | triangles | rays | query | threads | system | Mrays/s | octoray / system | hits |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(f"| {r[0]} | {r[1]} | {r[2]} | {r[3]} | {r[4]} | {r[5]} | {r[6]:.2f} | {r[7]:.2f}x | {r[8]} |")
    text = "\n".join(lines) + "\n"
    if args.out:
        with open(args.out, "w") as fh:
            fh.write(text)
    print(text)


if __name__ == "__main__":
    main()
