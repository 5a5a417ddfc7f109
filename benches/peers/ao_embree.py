"""Embree's occlusion rays beside kapaint's AO bake, on the same mesh and the same ray count.

Not part of kapaint: a peer measurement (pip install embreex numpy). It reads an OBJ, picks
surface points area-weighted (kapaint's atlas has one texel density, so its texels are too),
casts `rays` cosine-weighted directions around each point's geometric normal from just off
the surface (1e-5 of the bounding box's diagonal, as kapaint does), and times Embree's
occlusion queries alone (ray generation excluded), one thread. It prints rays per second and
the mean open fraction, which should match kapaint's mean AO on the same mesh.

    python ao_embree.py MESH.obj TOTAL_RAYS [RAYS_PER_POINT] [coherent]

With `coherent` each chunk's points are cast in Morton order (near points one after another, as
a bake walks its texels), as `examples/ao_rays.rs` orders its points with the same word.
"""

import sys
import time

import numpy as np
from embreex import rtcore_scene
from embreex.mesh_construction import TriangleMesh


def load_obj(path):
    vertices, faces = [], []
    with open(path) as f:
        for line in f:
            parts = line.split()
            if not parts:
                continue
            if parts[0] == "v":
                vertices.append([float(x) for x in parts[1:4]])
            elif parts[0] == "f":
                ids = [int(p.split("/")[0]) - 1 for p in parts[1:]]
                for k in range(1, len(ids) - 1):
                    faces.append([ids[0], ids[k], ids[k + 1]])
    return np.array(vertices, dtype=np.float32), np.array(faces, dtype=np.int64)


def morton_codes(points, lo, hi):
    """Each point's place along a Morton curve through the box `lo`..`hi` (21 bits an axis)."""
    scale = ((1 << 21) - 1) / max(float((hi - lo).max()), 1e-30)
    q = np.clip(((points - lo) * scale).astype(np.uint64), 0, (1 << 21) - 1)
    codes = np.zeros(len(points), dtype=np.uint64)
    for bit in range(21):
        for axis in range(3):
            codes |= ((q[:, axis] >> np.uint64(bit)) & np.uint64(1)) << np.uint64(3 * bit + 2 - axis)
    return codes


def main():
    path, total = sys.argv[1], int(sys.argv[2])
    per_point = int(sys.argv[3]) if len(sys.argv) > 3 else 64
    coherent = len(sys.argv) > 4 and sys.argv[4] == "coherent"
    v, f = load_obj(path)
    tris = v[f]
    scene = rtcore_scene.EmbreeScene()
    TriangleMesh(scene, tris)
    cross = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    area = np.linalg.norm(cross, axis=1)
    keep = area > 0
    normals = cross[keep] / area[keep, None]
    tris_k, area_k = tris[keep], area[keep]
    diagonal = float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))
    rng = np.random.default_rng(1)
    points = total // per_point
    chunk_points = max(1, 4_000_000 // per_point)
    seconds, open_rays, cast = 0.0, 0, 0
    done = 0
    while done < points:
        n = min(chunk_points, points - done)
        t = rng.choice(len(area_k), size=n, p=area_k / area_k.sum())
        r1, r2 = rng.random(n), rng.random(n)
        s = np.sqrt(r1)
        bary = np.stack([1 - s, s * (1 - r2), s * r2], axis=1).astype(np.float32)
        p = np.einsum("nk,nkj->nj", bary, tris_k[t])
        nrm = normals[t]
        if coherent:
            order = np.argsort(morton_codes(p, v.min(axis=0), v.max(axis=0)), kind="stable")
            p, nrm = p[order], nrm[order]
        origin = p + nrm * (1e-5 * diagonal)
        # A frame per point, then cosine-weighted directions.
        helper = np.where(np.abs(nrm[:, :1]) > 0.9, [[0.0, 1.0, 0.0]], [[1.0, 0.0, 0.0]])
        tx = np.cross(nrm, helper)
        tx /= np.linalg.norm(tx, axis=1, keepdims=True)
        ty = np.cross(nrm, tx)
        u, w = rng.random((n, per_point)), rng.random((n, per_point))
        rad, phi = np.sqrt(u), 2 * np.pi * w
        d = (
            tx[:, None, :] * (rad * np.cos(phi))[..., None]
            + ty[:, None, :] * (rad * np.sin(phi))[..., None]
            + nrm[:, None, :] * np.sqrt(np.maximum(0.0, 1 - u))[..., None]
        )
        origins = np.repeat(origin, per_point, axis=0).astype(np.float32)
        dirs = d.reshape(-1, 3).astype(np.float32)
        start = time.perf_counter()
        hit = scene.run(origins, dirs, query="OCCLUDED")
        seconds += time.perf_counter() - start
        open_rays += int(np.count_nonzero(np.asarray(hit) == -1))
        cast += len(dirs)
        done += n
    print(
        f"embree: {cast} rays in {seconds:.2f} s, {cast / seconds / 1e6:.2f} M rays/s "
        f"(one thread{', Morton order' if coherent else ''}), mean open fraction {open_rays / cast:.4f}"
    )


if __name__ == "__main__":
    main()
