#!/usr/bin/env python3
"""Disk conformal maps side by side: `beltrami qc MESH --target disk --conformal`
against Boundary First Flattening (Sawhney and Crane 2017, `bff-command-line MESH OUT
--flattenToDisk`), both measured by the shared independent measure
`../shared/peers/qcmeasure.py --mode vt` (per-face |mu|, mean over faces unweighted, and
flipped faces) and by how far each boundary lies from a circle: the boundary vertices'
largest | |p - c| - r | / r, with c and r the centre and radius of the unit circle for
beltrami and Choi-Lui (their target) and of the least-squares circle for BFF (which
scales and places its disk freely).

BFF is built once from source with cmake and SuiteSparse (Debian:
`apt-get install cmake libsuitesparse-dev`) under ~/.cache/beltrami/bff: from
`--bff-source DIR` (a checkout with its `deps/rectangle-bin-pack`), else by
`git clone --recursive https://github.com/GeometryCollective/boundary-first-flattening`.
`--bff PATH` takes a built `bff-command-line` instead. Times are wall-clock seconds of
whole processes (read, map, write) for both, alternating peer and ours, `--rounds`
rounds; the table shows each run. With GNU Octave installed (`apt-get install octave`)
the Choi-Lui disk map (`../shared/peers/choi/disk.sh`) runs as a third method, timed
the same way (its whole process includes Octave's start-up). Not part of CI. Usage
(from the repository root):

    python3 benches/peers/bff_compare.py [--meshes ../shared/meshes] [--beltrami BIN]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from peer_scripts import bootstrap, timed

ROOT = Path(__file__).resolve().parents[2]
CACHE = Path.home() / ".cache" / "beltrami" / "bff"
QCMEASURE = ROOT.parent / "shared" / "peers" / "qcmeasure.py"
CHOI = ROOT.parent / "shared" / "peers" / "choi" / "disk.sh"


def build_bff(source: Path | None) -> Path:
    """The path of `bff-command-line`, built under CACHE when missing."""
    binary = CACHE / "build" / "bff-command-line"
    if binary.exists():
        return binary
    if source is None:
        source = CACHE / "src"
        if not source.exists():
            subprocess.run(
                ["git", "clone", "--recursive", "--depth", "1",
                 "https://github.com/GeometryCollective/boundary-first-flattening", str(source)],
                check=True,
            )
    build = CACHE / "build"
    build.mkdir(parents=True, exist_ok=True)
    subprocess.run(
        ["cmake", str(source.resolve()), "-DBFF_BUILD_GUI=OFF", "-DCMAKE_BUILD_TYPE=Release"],
        cwd=build, check=True,
    )
    subprocess.run(["make", f"-j{os.cpu_count() or 1}", "bff-command-line"], cwd=build, check=True)
    return binary


def measure(mesh: Path, mapped: Path) -> dict:
    """qcmeasure's JSON for a map given by `vt`."""
    run = subprocess.run(
        [sys.executable, str(QCMEASURE), str(mesh), str(mapped), "--mode", "vt", "--json"],
        capture_output=True, text=True, check=True,
    )
    return json.loads(run.stdout)


def boundary_off_circle(mesh: Path, mapped: Path, unit: bool) -> float:
    """The boundary vertices' largest relative distance from the circle (the unit circle
    when `unit`, else their least-squares circle)."""
    faces, corner_vt, vts = [], [], []
    with open(mapped) as f:
        for line in f:
            if line.startswith("vt "):
                vts.append([float(t) for t in line.split()[1:3]])
            elif line.startswith("f "):
                parts = [p.split("/") for p in line.split()[1:]]
                faces.append([int(p[0]) - 1 for p in parts])
                corner_vt.append([int(p[1]) - 1 for p in parts])
    # Boundary edges: directed edges without their reverse.
    directed = {}
    for face, vt in zip(faces, corner_vt):
        for k in range(len(face)):
            directed[(face[k], face[(k + 1) % len(face)])] = vt[k]
    points = [vts[t] for (a, b), t in directed.items() if (b, a) not in directed]
    if unit:
        cx, cy, r = 0.0, 0.0, 1.0
    else:
        # Kasa's algebraic fit: x^2 + y^2 = 2 cx x + 2 cy y + c.
        n = len(points)
        sx = sum(p[0] for p in points); sy = sum(p[1] for p in points)
        sxx = sum(p[0] ** 2 for p in points); syy = sum(p[1] ** 2 for p in points)
        sxy = sum(p[0] * p[1] for p in points)
        sz = sum(p[0] ** 2 + p[1] ** 2 for p in points)
        szx = sum((p[0] ** 2 + p[1] ** 2) * p[0] for p in points)
        szy = sum((p[0] ** 2 + p[1] ** 2) * p[1] for p in points)
        a = [[2 * sxx, 2 * sxy, sx], [2 * sxy, 2 * syy, sy], [2 * sx, 2 * sy, n]]
        b = [szx, szy, sz]
        cx, cy, c = solve3(a, b)
        r = math.sqrt(c + cx * cx + cy * cy)
    return max(abs(math.hypot(p[0] - cx, p[1] - cy) - r) / r for p in points)


def solve3(a, b):
    """Cramer's rule for a 3 x 3 system."""
    def det(m):
        return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))
    d = det(a)
    out = []
    for k in range(3):
        m = [row[:] for row in a]
        for i in range(3):
            m[i][k] = b[i]
        out.append(det(m) / d)
    return out


def main() -> None:
    # qcmeasure needs numpy: run in the peers' virtual environment.
    bootstrap(__file__, ["numpy"], "import numpy")
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--meshes", type=Path, default=ROOT.parent / "shared" / "meshes")
    parser.add_argument("--beltrami", type=Path, default=ROOT / "target" / "release" / "beltrami")
    parser.add_argument("--bff", type=Path, help="a built bff-command-line")
    parser.add_argument("--bff-source", type=Path, help="a BFF checkout to build")
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--mesh", action="append", help="a mesh's name (repeatable)")
    parser.add_argument("--choi", type=Path, default=CHOI,
                        help="the Choi-Lui driver disk.sh (run when octave-cli is installed)")
    args = parser.parse_args()
    bff = args.bff or build_bff(args.bff_source)
    names = args.mesh or ["disk_human_face", "disk_hand"]
    with_choi = args.choi.exists() and shutil.which("octave-cli") is not None
    if not with_choi:
        print(f"(Choi-Lui left out: needs {args.choi} and octave-cli)", file=sys.stderr)
    print("| mesh | method | seconds (each round) | mean / max \\|mu\\| | flips | boundary off the circle |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for name in names:
            mesh = args.meshes / f"{name}.obj"
            outputs = {"BFF": Path(tmp) / f"{name}.bff.obj", "beltrami": Path(tmp) / f"{name}.ours.obj"}
            commands = {
                "BFF": [str(bff), str(mesh), str(outputs["BFF"]), "--flattenToDisk"],
                "beltrami": [str(args.beltrami), "qc", str(mesh), "--target", "disk", "--conformal",
                             "-o", str(outputs["beltrami"]), "-q"],
            }
            if with_choi:
                outputs["Choi-Lui"] = Path(tmp) / f"{name}.choi.obj"
                commands["Choi-Lui"] = [str(args.choi), str(mesh), str(outputs["Choi-Lui"])]
            seconds = {k: [] for k in commands}
            for _ in range(args.rounds):
                for method, command in commands.items():
                    seconds[method].append(timed(command))
            for method, out in outputs.items():
                m = measure(mesh, out)
                off = boundary_off_circle(mesh, out, unit=(method != "BFF"))
                mean, top = m["mu_mean"], m["mu_max"]
                flips = m["flipped"]
                times = ", ".join(f"{s:.3f}" for s in seconds[method])
                print(f"| {name} | {method} | {times} | {mean:.5f} / {top:.3f} | {flips} | {off:.2e} |")


if __name__ == "__main__":
    main()
