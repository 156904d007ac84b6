#!/usr/bin/env python3
"""Check a registration's output against the target's own face normals.

    python3 benches/register_outside_check.py SOURCE TARGET OUT.obj CORRESPONDENCE.txt

SOURCE and TARGET are the meshes given to `beltrami register`, OUT.obj and
CORRESPONDENCE.txt its `-o` and `--correspondence` outputs. The check does not use the
flow's own flip rule (a face against the sum of the target's interpolated vertex
normals at its corners' images): each source face's image triangle, taken from OUT.obj,
is compared with the normals of the three target faces its corners lie on (the first
number of each correspondence line). It prints how many faces have no normal to
compare (an image triangle or a corner's target face of zero area), how many point
against all three,
against two or more, against at least one, and the lowest over faces of the best of the
three cosines, with the angles between the corner faces of the faces counted: a face
whose corners sit on target faces far apart in angle spans a fold or a ridge of the
target, where a flat triangle cannot face every sheet.

Plain Python (no numpy), OBJ files with `v` and `f` lines (1-based, `v/vt/vn` forms and
polygons as their first three corners: a registration output keeps the source's faces).
"""

import math
import sys


def read_obj(path):
    positions, faces = [], []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                positions.append(tuple(map(float, line.split()[1:4])))
            elif line.startswith("f "):
                faces.append(tuple(int(t.split("/")[0]) - 1 for t in line.split()[1:4]))
    return positions, faces


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cosine(a, b):
    return dot(a, b) / math.sqrt(dot(a, a) * dot(b, b))


def normal(positions, face):
    a, b, c = (positions[i] for i in face)
    return cross(sub(b, a), sub(c, a))


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    source, target, output, correspondence = sys.argv[1:]
    _, source_faces = read_obj(source)
    target_positions, target_faces = read_obj(target)
    image, _ = read_obj(output)
    with open(correspondence) as f:
        under = [int(line.split()[0]) for line in f if line.strip()]
    target_normals = [normal(target_positions, f) for f in target_faces]

    against = [0, 0, 0, 0]
    lowest_best = 1.0
    spread = []
    degenerate = 0
    for face in source_faces:
        n = normal(image, face)
        corner_normals = [target_normals[under[v]] for v in face]
        # A zero normal has no side: such faces are counted apart, not compared.
        if dot(n, n) == 0.0 or any(dot(m, m) == 0.0 for m in corner_normals):
            degenerate += 1
            continue
        cosines = [cosine(n, m) for m in corner_normals]
        against[sum(c < 0 for c in cosines)] += 1
        lowest_best = min(lowest_best, max(cosines))
        if min(cosines) < 0:
            widest = min(cosine(corner_normals[i], corner_normals[j]) for i, j in ((0, 1), (0, 2), (1, 2)))
            spread.append(math.degrees(math.acos(max(-1.0, min(1.0, widest)))))
    print(f"faces {len(source_faces)}")
    print(f"degenerate (an image or corner face of zero area): {degenerate}")
    print(f"against all three corner faces: {against[3]}")
    print(f"against two or more: {against[2] + against[3]}")
    print(f"against at least one: {against[1] + against[2] + against[3]}")
    print(f"lowest best cosine: {lowest_best:.3f}")
    if spread:
        print(f"widest angle between the corner faces of those: {min(spread):.0f}-{max(spread):.0f} degrees")


if __name__ == "__main__":
    main()
