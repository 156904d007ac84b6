#!/usr/bin/env python3
"""Side-by-side remeshing benchmark: `beltrami remesh` against pymeshlab's isotropic
explicit remeshing, at the same target edge length (a fraction of the bounding-box
diagonal), both timed as whole processes and both measured by this script with the same
code: corner angles with numpy, and the two-sided Hausdorff and mean distances with
pymeshlab's sampled Hausdorff filter (vertices, edges and faces sampled, both ways).

Usage:
  peer_pymeshlab.py BELTRAMI_BINARY OUT_DIR MESH [MESH ...] [--fraction 0.01] [--runs 3]
  peer_pymeshlab.py --remesh MESH OUT LENGTH        (the pymeshlab side, run as a process)

Needs `pip install pymeshlab numpy`. Prints one markdown table row per mesh and tool.
"""
import argparse
import json
import statistics
import sys

import numpy as np

from peer_scripts import timed


def pymeshlab_remesh(mesh, out, length):
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(mesh)
    ms.meshing_isotropic_explicit_remeshing(targetlen=pymeshlab.PureValue(length))
    ms.save_current_mesh(out, save_vertex_normal=False)


def diagonal(mesh):
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(mesh)
    return ms.current_mesh().bounding_box().diagonal()


def measure(source, result):
    """Angles of `result`, and distances between `result` and `source`."""
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(source)
    ms.load_new_mesh(result)
    m = ms.mesh(1)
    v, f = m.vertex_matrix(), m.face_matrix()
    p = v[f]
    angles = []
    for k in range(3):
        a = p[:, (k + 1) % 3] - p[:, k]
        b = p[:, (k + 2) % 3] - p[:, k]
        c = np.einsum("ij,ij->i", a, b) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
        angles.append(np.degrees(np.arccos(np.clip(c, -1.0, 1.0))))
    angles = np.concatenate(angles)
    edges = np.concatenate([np.linalg.norm(p[:, (k + 1) % 3] - p[:, k], axis=1) for k in range(3)])
    samples = 20 * max(m.vertex_number(), ms.mesh(0).vertex_number())
    there = ms.get_hausdorff_distance(sampledmesh=1, targetmesh=0, samplevert=True,
                                      sampleedge=True, sampleface=True, samplenum=samples)
    back = ms.get_hausdorff_distance(sampledmesh=0, targetmesh=1, samplevert=True,
                                     sampleedge=True, sampleface=True, samplenum=samples)
    return {
        "vertices": m.vertex_number(),
        "faces": m.face_number(),
        "min_angle": float(angles.min()),
        "under_30": float((angles < 30.0).mean()),
        "edge_mean": float(edges.mean()),
        "edge_spread": float(edges.std() / edges.mean()),
        "hausdorff": max(there["max"], back["max"]),
        "mean_distance": (there["mean"] + back["mean"]) / 2.0,
    }


def main():
    if len(sys.argv) > 1 and sys.argv[1] == "--remesh":
        pymeshlab_remesh(sys.argv[2], sys.argv[3], float(sys.argv[4]))
        return
    parser = argparse.ArgumentParser()
    parser.add_argument("beltrami")
    parser.add_argument("out_dir")
    parser.add_argument("meshes", nargs="+")
    parser.add_argument("--fraction", type=float, default=0.01)
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    print("| mesh | tool | vertices | min angle | angles < 30 | Hausdorff / diag | mean dist / diag | mean edge / L | seconds (median) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for mesh in args.meshes:
        name = mesh.rsplit("/", 1)[-1].removesuffix(".obj")
        diag = diagonal(mesh)
        length = args.fraction * diag
        ours = f"{args.out_dir}/{name}.beltrami.obj"
        theirs = f"{args.out_dir}/{name}.pymeshlab.obj"
        commands = {
            "beltrami": [args.beltrami, "-q", "remesh", mesh, "--edge-length", repr(length), "-o", ours],
            "pymeshlab": [sys.executable, __file__, "--remesh", mesh, theirs, repr(length)],
        }
        seconds = {tool: [] for tool in commands}
        for _ in range(args.runs):  # alternating runs: the machines are noisy
            for tool, cmd in commands.items():
                seconds[tool].append(timed(cmd))
        for tool, out in (("beltrami", ours), ("pymeshlab", theirs)):
            q = measure(mesh, out)
            print(f"| {name} | {tool} | {q['vertices']} | {q['min_angle']:.2f} | "
                  f"{100 * q['under_30']:.3f}% | {100 * q['hausdorff'] / diag:.3f}% | "
                  f"{100 * q['mean_distance'] / diag:.4f}% | {q['edge_mean'] / length:.3f} | "
                  f"{statistics.median(seconds[tool]):.2f} |", flush=True)
            print(json.dumps({"mesh": name, "tool": tool, **q}), file=sys.stderr)


if __name__ == "__main__":
    main()
