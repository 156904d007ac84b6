#!/usr/bin/env python3
"""Reading mesh files, side by side: `beltrami bench load` (parse, then the halfedge
build with its validation) against trimesh's `load`, on the same files.

The files: a unit-square grid of about `--triangles` triangles written by trimesh as
binary PLY, binary STL, OFF and OBJ. trimesh reads PLY, OFF and OBJ with
`process=False` (no validation, no merging); STL with `process=True`, the default,
because an STL file lists every triangle's corners and only merging makes them a mesh
(beltrami welds them while reading). Each figure is the fastest of `--repeat` runs.

It installs trimesh into a virtual environment under ~/.cache/beltrami/peers-venv (or
$BELTRAMI_PEERS_VENV) and re-runs itself there. It is not part of CI. Usage (from the
repository root, after `cargo build --release`):

    python3 benches/peers/load_compare.py [--triangles 1000000] [--repeat 3]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import tempfile
import time
from pathlib import Path

from peer_scripts import bootstrap

ROOT = Path(__file__).resolve().parents[2]
REQUIREMENTS = ["trimesh", "numpy"]


def beltrami_binary() -> Path:
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    return target / "release" / "beltrami"


def grid(n: int):
    import numpy as np

    x, y = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1))
    vertices = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    i, j = np.meshgrid(np.arange(n), np.arange(n))
    a = (j * (n + 1) + i).ravel()
    b, c, d = a + 1, a + n + 2, a + n + 1
    faces = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    return vertices, faces


def best(f, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        f()
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--triangles", type=int, default=1_000_000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    import trimesh

    n = max(1, round((args.triangles / 2) ** 0.5))
    vertices, faces = grid(n)
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    print(f"grid {n}x{n}: {len(vertices)} vertices, {len(faces)} triangles; trimesh {trimesh.__version__}")
    print("| file | MB | beltrami read + build s | trimesh load s | trimesh / beltrami |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as folder:
        for name, kind in [("ply", {"encoding": "binary"}), ("stl", {}), ("off", {}), ("obj", {})]:
            path = Path(folder) / f"grid.{name}"
            mesh.export(path, **kind)
            run = subprocess.run(
                [str(beltrami_binary()), "bench", "load", "--triangles", "2", "--mesh", str(path),
                 "--repeat", str(args.repeat), "--json"],
                capture_output=True, text=True, check=True,
            )
            ours = json.loads(run.stdout.strip().splitlines()[-1])
            ours_s = ours["parse_s"] + ours["build_s"]
            process = name == "stl"
            theirs = best(lambda: trimesh.load(path, process=process), args.repeat)
            mb = path.stat().st_size / 1e6
            print(f"| {name} | {mb:.1f} | {ours_s:.3f} | {theirs:.3f} | {theirs / ours_s:.1f}x |")


if __name__ == "__main__":
    bootstrap(__file__, REQUIREMENTS, "import trimesh")
    main()
