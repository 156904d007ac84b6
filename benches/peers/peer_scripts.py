"""What the peer comparison scripts share.

`bootstrap(script, requirements, probe)` re-runs the calling script with the Python of
a virtual environment under ~/.cache/beltrami/peers-venv (or $BELTRAMI_PEERS_VENV),
creating it and installing `requirements` when the import statement `probe` fails
there; `read_obj` reads an OBJ's positions and polygons; `ClosestPoints` finds the exact
closest points of a triangle mesh (numpy and scipy), which trimesh's
`proximity.closest_point` does not always (on `disk_human_face` it missed points lying
on the mesh by up to 2.3e-4, a sixth of a face).
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

VENV = Path(
    os.environ.get(
        "BELTRAMI_PEERS_VENV", Path.home() / ".cache" / "beltrami" / "peers-venv"
    )
)


def timed(command: list[str]) -> float:
    """Runs `command`, failing loudly, and returns its wall-clock seconds."""
    start = time.perf_counter()
    run = subprocess.run(command, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if run.returncode != 0:
        sys.exit(f"{' '.join(command)} failed:\n{run.stderr}")
    return seconds


def bootstrap(script: str, requirements: list[str], probe: str) -> None:
    """Returns when already running in the venv; otherwise prepares it and re-runs
    `script` there with the same arguments (does not return)."""
    python = VENV / "bin" / "python"
    if Path(sys.prefix).resolve() == VENV.resolve():
        return
    if not python.exists():
        print(f"creating {VENV}", file=sys.stderr)
        VENV.parent.mkdir(parents=True, exist_ok=True)
        subprocess.run([sys.executable, "-m", "venv", str(VENV)], check=True)
    if subprocess.run([str(python), "-c", probe], capture_output=True).returncode != 0:
        print(f"installing {' '.join(requirements)} into {VENV}", file=sys.stderr)
        subprocess.run(
            [str(python), "-m", "pip", "install", "-q", *requirements], check=True
        )
    os.execv(str(python), [str(python), str(Path(script).resolve()), *sys.argv[1:]])


def read_obj(path: Path):
    """Positions (an (n, 3) array) and polygons (lists of 0-based indices) of an OBJ, in
    the file's order."""
    import numpy as np

    positions, faces = [], []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                positions.append([float(t) for t in line.split()[1:4]])
            elif line.startswith("f "):
                faces.append([int(t.split("/")[0]) - 1 for t in line.split()[1:]])
    return np.array(positions, dtype=np.float64), faces


def closest_on_triangles(p, a, b, c):
    """The closest points of triangles `a b c` to points `p` (rows), with their
    barycentric coordinates: the Voronoi regions of the corners, the edges and the
    inside (Ericson, Real-Time Collision Detection, 5.1.5)."""
    import numpy as np

    def dot(x, y):
        return (x * y).sum(1)

    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = dot(ab, ap), dot(ac, ap)
    bp = p - b
    d3, d4 = dot(ab, bp), dot(ac, bp)
    cp = p - c
    d5, d6 = dot(ab, cp), dot(ac, cp)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        total = va + vb + vc
        weights = np.stack([va / total, vb / total, vc / total], axis=1)
        t_ab = d1 / (d1 - d3)
        t_ac = d2 / (d2 - d6)
        t_bc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
    regions = [
        (d1 <= 0) & (d2 <= 0),
        (d3 >= 0) & (d4 <= d3),
        (vc <= 0) & (d1 >= 0) & (d3 <= 0),
        (d6 >= 0) & (d5 <= d6),
        (vb <= 0) & (d2 >= 0) & (d6 <= 0),
        (va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0),
    ]
    one, zero = np.ones_like(d1), np.zeros_like(d1)
    choices = [
        np.stack([one, zero, zero], 1),
        np.stack([zero, one, zero], 1),
        np.stack([1 - t_ab, t_ab, zero], 1),
        np.stack([zero, zero, one], 1),
        np.stack([1 - t_ac, zero, t_ac], 1),
        np.stack([zero, 1 - t_bc, t_bc], 1),
    ]
    decided = np.zeros(len(p), dtype=bool)
    for region, choice in zip(regions, choices):
        take = region & ~decided
        weights[take] = choice[take]
        decided |= region
    found = weights[:, :1] * a + weights[:, 1:2] * b + weights[:, 2:] * c
    return found, weights


class ClosestPoints:
    """The exact closest points of a triangle mesh: the faces whose centroid is within
    the distance to the nearest centroid plus the largest centroid-to-corner distance
    hold the closest point of any query; each is tried exactly, the lowest face id
    winning ties."""

    def __init__(self, positions, faces):
        import numpy as np
        from scipy.spatial import cKDTree

        self.positions = np.asarray(positions, dtype=np.float64)
        self.faces = np.asarray(faces, dtype=np.int64)
        corners = self.positions[self.faces]
        centroids = corners.mean(1)
        self.reach = float(np.linalg.norm(corners - centroids[:, None], axis=2).max())
        self.tree = cKDTree(centroids)

    def query(self, points):
        """Per point (rows): the face holding its closest point, the barycentric
        coordinates there and the closest point itself."""
        import numpy as np

        points = np.asarray(points, dtype=np.float64)
        nearest, _ = self.tree.query(points)
        candidates = self.tree.query_ball_point(points, nearest + self.reach + 1e-12)
        query = np.repeat(np.arange(len(points)), [len(c) for c in candidates])
        faces = np.concatenate([np.sort(c) for c in candidates]).astype(np.int64)
        a, b, c = (self.positions[self.faces[faces, k]] for k in range(3))
        found, weights = closest_on_triangles(points[query], a, b, c)
        distance = np.linalg.norm(found - points[query], axis=1)
        order = np.lexsort((faces, distance, query))
        first = order[np.r_[True, query[order][1:] != query[order][:-1]]]
        return faces[first], weights[first], found[first]
