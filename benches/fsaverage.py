#!/usr/bin/env python3
"""Cortical surfaces for registration benchmarks, from nilearn's package data.

    python3 benches/fsaverage.py OUT_DIR [--landmarks N]

Downloads nilearn's wheel from PyPI (`pip download --no-deps nilearn`) and writes, for
each hemisphere (left, right) and surface (white, pial, infl, sphere) of FreeSurfer's
fsaverage5 template (10,242 vertices, 20,480 triangles), `OUT_DIR/fs5_{hemi}_{surf}.obj`.
Within one hemisphere vertex i of every surface is the same point of the cortex, so a
registration of one surface onto another has a known answer: vertex i goes to vertex i.

It also writes the per-vertex fields of each hemisphere, `OUT_DIR/fs5_{hemi}_{field}.txt`
(one value per line, in vertex order): `sulc` (sulcal depth) and `curv` (curvature of the
white surface), for `beltrami register SRC TGT --features F F` (vertex i of every surface
has the same value, the fields agree under the true correspondence).

With `--subdivide` it also writes every surface and field split once 1-to-4 at edge
midpoints, `OUT_DIR/fs5s_{hemi}_{name}.obj` and `.txt` (40,962 vertices, 81,920 faces:
the same piecewise-flat surface, midpoints numbered alike on every surface of a
hemisphere, so vertex i still corresponds to vertex i; a midpoint's field value is the
mean of its edge's), for the issue's 65K-face goal.

With `--landmarks N` it also writes `OUT_DIR/fs5_landmarks_N.txt`: N landmarks `v I I`
spread over the white surface by farthest-point sampling (geodesic distance along
edges), for `beltrami register SRC TGT --landmarks`.

Plain Python: the GIFTI files are gzip-compressed XML whose data arrays are
base64-encoded, zlib-compressed little-endian arrays (float32 positions, int32 faces).
"""

import argparse
import base64
import glob
import gzip
import heapq
import math
import os
import struct
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
import zipfile
import zlib

SURFACES = {
    "white": "white_{h}.gii.gz",
    "pial": "pial_{h}.gii.gz",
    "infl": "infl_{h}.gii.gz",
    "sphere": "sphere_{h}.gii.gz",
}


FIELDS = {
    "sulc": "sulc_{h}.gii.gz",
    "curv": "curv_{h}.gii.gz",
}


def wheel(given):
    if given:
        return given
    folder = tempfile.mkdtemp()
    subprocess.run(
        [sys.executable, "-m", "pip", "download", "--quiet", "--no-deps", "nilearn", "-d", folder],
        check=True,
    )
    found = glob.glob(os.path.join(folder, "nilearn-*.whl"))
    if not found:
        sys.exit("pip download gave no nilearn wheel")
    return found[0]


def data_arrays(raw):
    """The data arrays of a GIFTI file as (intent, values)."""
    root = ET.fromstring(gzip.decompress(raw))
    arrays = []
    for array in root.iter("DataArray"):
        data = array.find("Data").text.strip()
        payload = base64.b64decode(data)
        if array.get("Encoding") == "GZipBase64Binary":
            payload = zlib.decompress(payload)
        kind = array.get("DataType")
        code = {"NIFTI_TYPE_FLOAT32": "f", "NIFTI_TYPE_INT32": "i"}[kind]
        count = len(payload) // 4
        order = "<" if array.get("Endian", "LittleEndian") == "LittleEndian" else ">"
        values = struct.unpack(f"{order}{count}{code}", payload)
        arrays.append((array.get("Intent"), values))
    return arrays


def surface(raw):
    positions, faces = None, None
    for intent, values in data_arrays(raw):
        if intent == "NIFTI_INTENT_POINTSET":
            positions = [values[i : i + 3] for i in range(0, len(values), 3)]
        elif intent == "NIFTI_INTENT_TRIANGLE":
            faces = [values[i : i + 3] for i in range(0, len(values), 3)]
    return positions, faces


def write_obj(path, positions, faces, source):
    with open(path, "w") as f:
        f.write(f"# FreeSurfer fsaverage5 ({source}), from nilearn's package data\n")
        for p in positions:
            f.write(f"v {p[0]!r} {p[1]!r} {p[2]!r}\n")
        for a, b, c in faces:
            f.write(f"f {a + 1} {b + 1} {c + 1}\n")


def midpoints(faces):
    """The edges split by a 1-to-4 subdivision, numbered after the vertices in the order
    they are met, and the new faces (corners, then the three edge midpoints)."""
    index, new_faces = {}, []
    def mid(a, b):
        return index.setdefault((min(a, b), max(a, b)), len(index))
    for a, b, c in faces:
        ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
        new_faces.append((a, b, c, ab, bc, ca))
    return index, new_faces


def subdivided(values, faces, n):
    """Per-vertex `values` (tuples or numbers) of a mesh with `n` vertices and its
    1-to-4 subdivision's faces."""
    index, new_faces = midpoints(faces)
    out = list(values)
    for (a, b), _ in sorted(index.items(), key=lambda item: item[1]):
        va, vb = values[a], values[b]
        out.append(tuple((x + y) / 2 for x, y in zip(va, vb)) if isinstance(va, tuple) else (va + vb) / 2)
    tri = []
    for a, b, c, ab, bc, ca in new_faces:
        ab, bc, ca = n + ab, n + bc, n + ca
        tri += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
    return out, tri


def farthest_points(positions, faces, n):
    neighbours = [[] for _ in positions]
    for face in faces:
        for k in range(3):
            a, b = face[k], face[(k + 1) % 3]
            d = math.dist(positions[a], positions[b])
            neighbours[a].append((b, d))
            neighbours[b].append((a, d))
    distance = [math.inf] * len(positions)
    chosen = [0]
    for _ in range(n):
        heap = [(0.0, chosen[-1])]
        distance[chosen[-1]] = 0.0
        while heap:
            d, v = heapq.heappop(heap)
            if d > distance[v]:
                continue
            for w, length in neighbours[v]:
                if d + length < distance[w]:
                    distance[w] = d + length
                    heapq.heappush(heap, (d + length, w))
        chosen.append(max(range(len(positions)), key=distance.__getitem__))
    return chosen[1 : n + 1]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out")
    parser.add_argument("--landmarks", type=int, default=0)
    parser.add_argument("--wheel", help="a nilearn wheel already downloaded")
    parser.add_argument("--subdivide", action="store_true", help="also write the 1-to-4 subdivided surfaces and fields")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    with zipfile.ZipFile(wheel(args.wheel)) as z:
        for hemi in ("left", "right"):
            for name, pattern in FIELDS.items():
                member = "nilearn/datasets/data/fsaverage5/" + pattern.format(h=hemi)
                values = data_arrays(z.read(member))[0][1]
                path = os.path.join(args.out, f"fs5_{hemi}_{name}.txt")
                with open(path, "w") as f:
                    f.write(f"# FreeSurfer fsaverage5 {name}, {hemi} hemisphere, one value per vertex\n")
                    f.writelines(f"{x!r}\n" for x in values)
                print(f"{path}: {len(values)} values")
                if args.subdivide:
                    _, faces = surface(z.read("nilearn/datasets/data/fsaverage5/" + SURFACES["white"].format(h=hemi)))
                    fine, _ = subdivided(list(values), faces, len(values))
                    path = os.path.join(args.out, f"fs5s_{hemi}_{name}.txt")
                    with open(path, "w") as f:
                        f.write(f"# fsaverage5 {name}, {hemi} hemisphere, subdivided 1-to-4 (midpoints: edge means)\n")
                        f.writelines(f"{x!r}\n" for x in fine)
                    print(f"{path}: {len(fine)} values")
            for name, pattern in SURFACES.items():
                member = "nilearn/datasets/data/fsaverage5/" + pattern.format(h=hemi)
                positions, faces = surface(z.read(member))
                path = os.path.join(args.out, f"fs5_{hemi}_{name}.obj")
                write_obj(path, positions, faces, f"{name}, {hemi} hemisphere")
                print(f"{path}: {len(positions)} vertices, {len(faces)} faces")
                if args.subdivide:
                    fine, fine_faces = subdivided([tuple(p) for p in positions], faces, len(positions))
                    path = os.path.join(args.out, f"fs5s_{hemi}_{name}.obj")
                    write_obj(path, fine, fine_faces, f"{name}, {hemi} hemisphere, subdivided 1-to-4")
                    print(f"{path}: {len(fine)} vertices, {len(fine_faces)} faces")
                if name == "white" and hemi == "left" and args.landmarks:
                    marks = farthest_points(positions, faces, args.landmarks)
                    lm = os.path.join(args.out, f"fs5_landmarks_{args.landmarks}.txt")
                    with open(lm, "w") as f:
                        f.write(f"# {args.landmarks} landmarks spread over fsaverage5 (vertex i onto vertex i)\n")
                        for v in marks:
                            f.write(f"v {v} {v}\n")
                    print(f"{lm}: {args.landmarks} landmarks")


if __name__ == "__main__":
    main()
