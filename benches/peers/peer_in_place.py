#!/usr/bin/env python3
"""Side-by-side in-place remeshing benchmark: `beltrami remesh --method qc-angles` against
pymeshlab's tangential relaxation (its isotropic remeshing with splits, collapses and
flips off, smoothing and reprojection on: the same vertices and faces, moved along the
surface), both timed as whole processes and measured by this script with the same code:
corner angles of the polygons as written, the two-sided Hausdorff and mean distances to
the input with pymeshlab's sampled Hausdorff filter.

Usage:
  peer_in_place.py BELTRAMI_BINARY OUT_DIR MESH [MESH ...] [--ours ARGS] [--relax N]
  peer_in_place.py --relax MESH OUT ITERATIONS     (the pymeshlab side, run as a process)

Needs `pip install pymeshlab numpy`. Prints one markdown table row per mesh and tool
(the input, beltrami, pymeshlab with N relaxation passes for each N of --relax).
"""
import argparse
import json
import shlex
import sys

import numpy as np

from peer_scripts import read_obj, timed


def relax(mesh, out, iterations):
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(mesh)
    ms.meshing_isotropic_explicit_remeshing(
        iterations=iterations, splitflag=False, collapseflag=False, swapflag=False,
        smoothflag=True, reprojectflag=True)
    ms.save_current_mesh(out, save_vertex_normal=False)


def angles(path):
    v, faces = read_obj(path)
    out = []
    for n in sorted({len(f) for f in faces}):
        f = np.array([f for f in faces if len(f) == n])
        p = v[f]
        for k in range(n):
            a = p[:, (k + 1) % n] - p[:, k]
            b = p[:, (k - 1) % n] - p[:, k]
            c = np.einsum("ij,ij->i", a, b) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
            out.append(np.degrees(np.arccos(np.clip(c, -1.0, 1.0))))
    return np.concatenate(out), len(v), len(faces)


def distances(source, result):
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(source)
    ms.load_new_mesh(result)
    samples = 20 * ms.mesh(0).vertex_number()
    there = ms.get_hausdorff_distance(sampledmesh=1, targetmesh=0, samplevert=True,
                                      sampleedge=True, sampleface=True, samplenum=samples)
    back = ms.get_hausdorff_distance(sampledmesh=0, targetmesh=1, samplevert=True,
                                     sampleedge=True, sampleface=True, samplenum=samples)
    diag = ms.mesh(0).bounding_box().diagonal()
    return max(there["max"], back["max"]) / diag, (there["mean"] + back["mean"]) / 2 / diag


def row(name, tool, source, result, seconds):
    a, nv, nf = angles(result)
    hausdorff, mean = distances(source, result) if result != source else (0.0, 0.0)
    right = 90.0 if nf and len(read_obj(result)[1][0]) == 4 else 60.0
    print(f"| {name} | {tool} | {nv} | {a.min():.2f} | {100 * (a < 30).mean():.3f}% | "
          f"{np.abs(a - right).mean():.2f} | {100 * hausdorff:.3f}% | {100 * mean:.4f}% | "
          f"{seconds} |", flush=True)
    print(json.dumps({"mesh": name, "tool": tool, "min_angle": float(a.min()),
                      "under_30": float((a < 30).mean()), "hausdorff": hausdorff,
                      "mean_distance": mean}), file=sys.stderr)


def main():
    if len(sys.argv) > 1 and sys.argv[1] == "--relax":
        relax(sys.argv[2], sys.argv[3], int(sys.argv[4]))
        return
    parser = argparse.ArgumentParser()
    parser.add_argument("beltrami")
    parser.add_argument("out_dir")
    parser.add_argument("meshes", nargs="+")
    parser.add_argument("--ours", default="", help="extra arguments of beltrami remesh")
    parser.add_argument("--relax", default="10,50", help="pymeshlab relaxation passes")
    args = parser.parse_args()
    print("| mesh | tool | vertices | min angle | angles < 30 | mean deviation from 60 (90) | "
          "Hausdorff / diag | mean dist / diag | seconds |")
    print("|---|---|---|---|---|---|---|---|---|")
    for mesh in args.meshes:
        name = mesh.rsplit("/", 1)[-1].removesuffix(".obj")
        row(name, "input", mesh, mesh, "")
        ours = f"{args.out_dir}/{name}.qc-angles.obj"
        cmd = [args.beltrami, "-q", "remesh", mesh, "--method", "qc-angles", "-o", ours]
        seconds = timed(cmd + shlex.split(args.ours))
        row(name, f"beltrami qc-angles {args.ours}".strip(), mesh, ours, f"{seconds:.2f}")
        triangles = all(len(f) == 3 for f in read_obj(mesh)[1])
        for passes in (int(p) for p in args.relax.split(",") if p) if triangles else ():
            theirs = f"{args.out_dir}/{name}.relax{passes}.obj"
            seconds = timed([sys.executable, __file__, "--relax", mesh, theirs, str(passes)])
            row(name, f"pymeshlab relaxation x{passes}", mesh, theirs, f"{seconds:.2f}")


if __name__ == "__main__":
    main()
