#!/usr/bin/env python3
"""Flipped faces of a map onto a mesh, counted outside beltrami (numpy and scipy).

    python3 benches/peers/flip_check.py SOURCE OUT.obj TARGET

SOURCE is the source mesh (its faces), OUT.obj the map: the source's faces with every
vertex at its image on TARGET, as `beltrami register -o` writes it (any method's output
with the source's faces will do). The rule is the one `beltrami register` (its verdict
and report), `beltrami distortion SOURCE OUT --target TARGET` and `beltrami render
--target` count by (docs/register.md, "Flipped faces"), recomputed here from its
definition with its own closest points and normals:

- every image vertex is carried to its exact closest point on TARGET
  (`peer_scripts.ClosestPoints`), and the target's normal there is the angle-weighted
  vertex normals interpolated with the point's barycentric coordinates, normalized (the
  face's normal where that sum vanishes);
- a triangle is flipped when its image's area vector points against the sum of the
  normals at its three corners, `(Y1 - Y0) x (Y2 - Y0) . (n0 + n1 + n2) <= 0`; a quad
  when the image's bilinear area element `X_u x X_v` does so at one of its four Gauss
  points `(1/2 +- 1/(2 sqrt 3))^2`. A collapsed image counts as flipped.

Prints the number of faces and the flipped ones (their count and the first ten ids,
0-based in file order). Also importable: `flipped_faces(source_faces, images,
target_positions, target_faces)`. It installs numpy and scipy into the peers' virtual
environment (see peer_scripts.py) and re-runs itself there. TARGET must be a triangle
mesh.
"""

from __future__ import annotations

import math
import sys

from peer_scripts import ClosestPoints, bootstrap, read_obj

REQUIREMENTS = ["numpy", "scipy"]


def vertex_normals(positions, faces):
    """Angle-weighted unit vertex normals: per vertex, the sum over its faces of the
    corner angle times the face's unit normal, normalized."""
    import numpy as np

    v, f = positions, faces
    face_normals = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    face_normals /= np.linalg.norm(face_normals, axis=1)[:, None]
    normals = np.zeros_like(v)
    for k in range(3):
        e1 = v[f[:, (k + 1) % 3]] - v[f[:, k]]
        e2 = v[f[:, (k + 2) % 3]] - v[f[:, k]]
        angle = np.arctan2(np.linalg.norm(np.cross(e1, e2), axis=1), (e1 * e2).sum(1))
        np.add.at(normals, f[:, k], angle[:, None] * face_normals)
    return normals / np.linalg.norm(normals, axis=1)[:, None], face_normals


def flipped_faces(source_faces, images, target_positions, target_faces):
    """Per source face (a list of corner indices into `images`), whether its image is
    flipped on the target (module docs)."""
    import numpy as np

    positions = np.asarray(target_positions, dtype=np.float64)
    faces = np.asarray(target_faces, dtype=np.int64)
    vertex_n, face_n = vertex_normals(positions, faces)
    under, weights, located = ClosestPoints(positions, faces).query(images)
    normals = (weights[:, :, None] * vertex_n[faces[under]]).sum(1)
    length = np.linalg.norm(normals, axis=1)
    normals = np.where(
        (length > 1e-8)[:, None], normals / np.maximum(length, 1e-300)[:, None], face_n[under]
    )
    gauss = [0.5 - 0.5 / math.sqrt(3.0), 0.5 + 0.5 / math.sqrt(3.0)]
    flipped = np.zeros(len(source_faces), dtype=bool)
    for s, face in enumerate(source_faces):
        p = located[face]
        reference = normals[face].sum(0)
        if len(face) == 3:
            flipped[s] = np.cross(p[1] - p[0], p[2] - p[0]) @ reference <= 0.0
        else:
            for u in gauss:
                for w in gauss:
                    along_u = (1 - w) * (p[1] - p[0]) + w * (p[2] - p[3])
                    along_v = (1 - u) * (p[3] - p[0]) + u * (p[2] - p[1])
                    flipped[s] |= np.cross(along_u, along_v) @ reference <= 0.0
    return flipped


def main() -> None:
    bootstrap(__file__, REQUIREMENTS, "import numpy, scipy")
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    source, output, target = sys.argv[1:]
    _, source_faces = read_obj(source)
    images, _ = read_obj(output)
    target_positions, target_faces = read_obj(target)
    if any(len(f) != 3 for f in target_faces):
        sys.exit("TARGET must be a triangle mesh")
    flipped = flipped_faces(source_faces, images, target_positions, target_faces)
    named = [int(f) for f in flipped.nonzero()[0][:10]]
    print(f"faces {len(source_faces)}")
    print(f"flipped: {int(flipped.sum())} {named}")


if __name__ == "__main__":
    main()
