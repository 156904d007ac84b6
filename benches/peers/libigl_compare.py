#!/usr/bin/env python3
"""Compare `beltrami param` with libigl (python bindings) on the shared disk meshes.

For every disk mesh it checks that

- `beltrami param --solver lscm --pin vA --pin vB` equals `igl.lscm(V, F, [A, B],
  [[0, 0], [1, 0]])` (A, B two boundary vertices far apart), and
- `beltrami param --solver harmonic --boundary circle --pin vS` equals
  `igl.harmonic(V, F, b, igl.map_vertices_to_circle(V, b), 1)` with
  `b = igl.boundary_loop(F)` and `S = b[0]`: both place the loop by arc length, start at
  S with angle 0 and walk the circle so that the faces keep their orientation (igl's
  loop runs counter-clockwise with increasing angle, ours clockwise with decreasing
  angle), so the two boundary maps are the same,

as the largest per-vertex distance between the two maps over the map's diameter, and
it times the whole `beltrami param --solver lscm` process against a Python process
doing igl.read_triangle_mesh + igl.lscm + igl.writeOBJ (wall clock, best of N).

It installs its own dependencies (`pip install libigl numpy scipy`) into a virtual
environment under ~/.cache/beltrami/peers-venv (or $BELTRAMI_PEERS_VENV) and re-runs
itself there. It is not part of CI. Usage (from the repository root):

    python3 benches/peers/libigl_compare.py [--meshes ../shared/meshes] [--repeat 3]

Exits non-zero if a difference is above its tolerance (LSCM 1e-6, harmonic 1e-8).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from peer_scripts import bootstrap, read_obj

ROOT = Path(__file__).resolve().parents[2]
REQUIREMENTS = ["libigl>=2.6", "numpy", "scipy"]
MESHES = ["disk_hemisphere", "disk_human_face", "disk_hand", "quad_disk_inspired"]
LSCM_TOLERANCE = 1e-6
HARMONIC_TOLERANCE = 1e-8


def read_uv(path: Path):
    import numpy as np

    with open(path) as f:
        uv = [[float(t) for t in ln.split()[1:3]] for ln in f if ln.startswith("vt ")]
    return np.array(uv, dtype=np.float64)


def triangulated(mesh: Path, work: Path) -> tuple[Path, str]:
    """The mesh itself if it has only triangles, else a fan-triangulated copy."""
    positions, faces = read_obj(mesh)
    if all(len(f) == 3 for f in faces):
        return mesh, ""
    out = work / f"{mesh.stem}_tri.obj"
    with open(out, "w") as f:
        for x, y, z in positions.tolist():
            f.write(f"v {x!r} {y!r} {z!r}\n")
        for face in faces:
            for k in range(1, len(face) - 1):
                f.write(f"f {face[0] + 1} {face[k] + 1} {face[k + 1] + 1}\n")
    triangles = sum(len(f) - 2 for f in faces)
    return out, (
        f"{len(faces)} polygons split into {triangles} triangles "
        "(fans from their first vertex), for both"
    )


def far_boundary_pair(v, b):
    """Two boundary vertices far apart: the farthest from b[0], then the farthest from it."""
    import numpy as np

    d = np.linalg.norm(v[b] - v[b[0]], axis=1)
    a = int(b[int(np.argmax(d))])
    d = np.linalg.norm(v[b] - v[a], axis=1)
    return a, int(b[int(np.argmax(d))])


def diameter(uv) -> float:
    """The largest distance between two points of the map (over its convex hull)."""
    import numpy as np
    from scipy.spatial import ConvexHull

    hull = uv[ConvexHull(uv).vertices]
    return float(np.max(np.linalg.norm(hull[:, None, :] - hull[None, :, :], axis=2)))


def relative_difference(ours, theirs) -> float:
    import numpy as np

    if ours.shape != theirs.shape:
        raise SystemExit(f"shape mismatch: ours {ours.shape}, igl {theirs.shape}")
    return float(np.max(np.linalg.norm(ours - theirs, axis=1)) / diameter(theirs))


def flipped(uv, f) -> int:
    import numpy as np

    a, b, c = uv[f[:, 0]], uv[f[:, 1]], uv[f[:, 2]]
    u, w = b - a, c - a
    cross = u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]
    return int(np.sum(cross <= 0))


def run(cmd: list[str]) -> float:
    """Runs a command, failing loudly; returns its wall-clock seconds."""
    start = time.perf_counter()
    out = subprocess.run(cmd, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if out.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed:\n{out.stderr}")
    return seconds


IGL_JOB = """
import sys, time
t0 = time.perf_counter()
import numpy as np, igl
t1 = time.perf_counter()
v, f = igl.read_triangle_mesh(sys.argv[1])
t2 = time.perf_counter()
b = np.array([int(sys.argv[2]), int(sys.argv[3])], dtype=np.int64)
bc = np.array([[0.0, 0.0], [1.0, 0.0]])
uv = igl.lscm(v, f, b, bc)[0]
t3 = time.perf_counter()
igl.writeOBJ(sys.argv[4], v, f, TC=uv, FTC=f)
t4 = time.perf_counter()
print(t1 - t0, t2 - t1, t3 - t2, t4 - t3)
"""


def best_of(repeat: int, cmd: list[str]):
    """The fastest of `repeat` runs of `cmd`: (seconds, stdout)."""
    best = None
    for _ in range(repeat):
        start = time.perf_counter()
        out = subprocess.run(cmd, capture_output=True, text=True)
        seconds = time.perf_counter() - start
        if out.returncode != 0:
            raise SystemExit(f"{' '.join(cmd)} failed:\n{out.stderr}")
        if best is None or seconds < best[0]:
            best = (seconds, out.stdout)
    return best


def igl_lscm(v, f, a, b):
    import igl
    import numpy as np

    pins = np.array([a, b], dtype=np.int64)
    result = igl.lscm(v, f, pins, np.array([[0.0, 0.0], [1.0, 0.0]]))
    # libigl >= 2.6 returns (uv, Q); older bindings returned (ok, uv).
    return result[1] if isinstance(result[0], bool) else result[0]


def main() -> int:
    parser = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        epilog="Installs libigl, numpy and scipy into $BELTRAMI_PEERS_VENV "
        "(default ~/.cache/beltrami/peers-venv) on first use.",
    )
    parser.add_argument(
        "--meshes", type=Path, default=ROOT.parent / "shared" / "meshes",
        help="folder of the shared meshes (default ../shared/meshes)",
    )
    parser.add_argument("--repeat", type=int, default=3, help="timing runs (best of)")
    parser.add_argument(
        "--time",
        default="disk_hand",
        help="meshes to time, comma-separated, or `all` (default disk_hand)",
    )
    parser.add_argument(
        "--beltrami", type=Path, help="the binary (default: cargo build --release)"
    )
    args = parser.parse_args()
    bootstrap(__file__, REQUIREMENTS, 'import igl, numpy, scipy')
    import igl
    import numpy as np

    if args.beltrami is None:
        subprocess.run(["cargo", "build", "--release", "--quiet"], cwd=ROOT, check=True)
        target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
        args.beltrami = (ROOT / target / "release" / "beltrami").resolve()
    beltrami = str(args.beltrami)
    timed = set(MESHES if args.time == "all" else args.time.split(","))
    versions = subprocess.run(
        [sys.executable, "-m", "pip", "list", "--format=freeze"],
        capture_output=True,
        text=True,
    ).stdout.split()
    versions = [p for p in versions if p.split("==")[0] in ("libigl", "numpy", "scipy")]
    print(f"libigl comparison: {', '.join(versions)}, python {sys.version.split()[0]}")

    rows, notes, failed = [], [], False
    with tempfile.TemporaryDirectory(prefix="beltrami-peers-") as tmp:
        work = Path(tmp)
        for name in MESHES:
            source = args.meshes / f"{name}.obj"
            if not source.exists():
                notes.append(f"{name}: {source} is absent, skipped")
                continue
            mesh, note = triangulated(source, work)
            if note:
                notes.append(f"{name}: {note}")
            v, f = igl.read_triangle_mesh(str(mesh))
            bnd = igl.boundary_loop(f)
            a, b = far_boundary_pair(v, bnd)

            # LSCM, the same two pins.
            ours_lscm = work / f"{name}_lscm.obj"
            ours_cmd = [beltrami, "-q", "param", str(mesh), "--solver", "lscm",
                        "--pin", f"v{a}", "--pin", f"v{b}", "-o", str(ours_lscm)]
            run(ours_cmd)
            uv_igl = igl_lscm(v, f, a, b)
            uv_ours = read_uv(ours_lscm)
            d_lscm = relative_difference(uv_ours, uv_igl)

            # Harmonic onto the circle, both starting at igl's b[0].
            ours_harm = work / f"{name}_harmonic.obj"
            run([beltrami, "-q", "param", str(mesh), "--solver", "harmonic", "--boundary",
                 "circle", "--pin", f"v{int(bnd[0])}", "-o", str(ours_harm)])
            bc = igl.map_vertices_to_circle(np.asfortranarray(v), bnd.astype(np.int32))
            h_igl = igl.harmonic(v, f, bnd, bc, 1)
            h_ours = read_uv(ours_harm)
            d_harm = relative_difference(h_ours, h_igl)
            d_bnd = relative_difference(h_ours[bnd], h_igl[bnd])

            checks = (("lscm", d_lscm, LSCM_TOLERANCE), ("harmonic", d_harm, HARMONIC_TOLERANCE))
            for what, d, tol in checks:
                if not d <= tol:
                    failed = True
                    notes.append(f"{name}: {what} differs by {d:.2e} > {tol:.0e}")
            notes.append(
                f"{name}: lscm pins v{a}, v{b}; flipped faces ours {flipped(uv_ours, f)}, "
                f"igl {flipped(uv_igl, f)}; harmonic boundary difference {d_bnd:.1e}, "
                f"start v{int(bnd[0])}"
            )

            ours_s = igl_s = None
            if name in timed:
                ours_s, ours_out = best_of(args.repeat, ours_cmd[:3] + ["--json"] + ours_cmd[3:])
                igl_out = work / f"{name}_igl.obj"
                igl_cmd = [sys.executable, "-c", IGL_JOB, str(mesh), str(a), str(b), str(igl_out)]
                igl_s, igl_stages = best_of(args.repeat, igl_cmd)
                stages = json.loads(ours_out)["timings"]
                ours_stages = ", ".join(f"{t['stage']} {t['seconds']:.3f}" for t in stages)
                imp, read, lscm, write = (float(t) for t in igl_stages.split())
                notes.append(
                    f"{name} timing, fastest runs: ours {ours_s:.3f} s in all, solver stages "
                    f"{ours_stages} s; libigl {igl_s:.3f} s in all: import {imp:.3f}, "
                    f"read_triangle_mesh {read:.3f}, lscm {lscm:.3f}, writeOBJ {write:.3f} s"
                )
            rows.append((name, len(f), len(v), ours_s, igl_s, d_lscm, d_harm))

    print()
    print(
        "| mesh | vertices | faces | ours s | libigl s | libigl / ours "
        "| max rel. diff. lscm | max rel. diff. harmonic |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for name, faces, vertices, ours_s, igl_s, d_lscm, d_harm in rows:
        if ours_s is None:
            timing = "- | - | -"
        else:
            timing = f"{ours_s:.3f} | {igl_s:.3f} | {igl_s / ours_s:.1f}"
        print(f"| {name} | {vertices} | {faces} | {timing} | {d_lscm:.1e} | {d_harm:.1e} |")
    print()
    for note in notes:
        print(f"- {note}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
