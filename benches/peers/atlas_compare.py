#!/usr/bin/env python3
"""Texture atlases side by side: xatlas (the `xatlas` Python bindings, default options)
and, when given, `beltrami atlas`, both judged by one measure written here with numpy
and scipy only, so that neither side grades its own output.

An atlas is a triangle mesh (positions V, faces F) with per-corner texture coordinates
(UV, and per face the uv index of each corner, FUV). `measure(V, F, UV, FUV)` reports:

- `charts`: the connected components of the faces, two faces being joined across an
  edge when both use the same two uv indices at its two ends (the edge is not a seam).
  Equal coordinates under different indices count as a seam.
- `seam_length`, `seam_fraction`: the 3D length of the seam edges, and its share of the
  length of all edges (each undirected edge once). A seam edge is an interior edge (two
  or more faces) whose faces do not all use the same uv indices at its ends; a boundary
  edge of the mesh is never a seam.
- `l2_stretch`, `linf_stretch`: the stretch of the map S from the texture to the surface
  (Sander, Snyder, Gortler, Hoppe, "Texture mapping progressive meshes", SIGGRAPH 2001).
  Per face, S is affine; with Gamma >= gamma the singular values of its Jacobian,
  L2(T) = sqrt((Gamma^2 + gamma^2) / 2) and Linf(T) = Gamma. Overall
  L2 = sqrt(sum L2(T)^2 A3(T) / sum A3(T)) and Linf = max Gamma, both multiplied by
  sqrt(sum A2 / sum A3) (A2 the absolute uv area, A3 the surface area), which is the same
  as rescaling the texture to the surface's total area: 1 is an isometry up to scale.
  Faces whose uv area is degenerate (|A2| <= 1e-14 of the total) are left out of every
  sum (stretch, area distortion, overlaps) and counted as `degenerate_uv_faces`;
  flipped faces (below) stay in.
- `mirrored_charts`: charts whose signed uv area is negative. The mesh's faces are taken
  as counter-clockwise seen from outside, so a chart laid out as the surface is seen from
  outside has a positive area; a mirrored chart shows the texture mirror-imaged.
  `misoriented_edges` counts the interior edges whose two faces run the same way (an
  inconsistently oriented input makes this count meaningless).
- `flipped_faces`: faces whose signed uv area has the sign opposite to their chart's
  signed total (local fold-overs; a wholly mirrored chart has none).
- `overlapping_pairs`: pairs of uv triangles of different faces whose interiors
  intersect. The triangles (degenerate ones left out) go into a uniform grid of buckets
  over the uv bounding box; pairs sharing a bucket whose boxes meet are tested by
  separating axes (the six edge normals) after shrinking each triangle toward its
  centroid by a relative 1e-7, and must overlap by more than 1e-9 of the bounding box on
  every axis, so that triangles touching along an edge or at a corner do not count. The
  work stops after 10^7 candidate pairs (`overlap_capped` is then true and the count a
  lower bound).
- `area_distortion`: the surface-area-weighted mean of |log(A2' / A3)| per face, A2' the
  uv area rescaled to the same total as the surface; `in_unit_square`: whether every
  used uv lies in [0, 1]^2 (to 1e-12); `uv_area`: the total absolute uv area (the share
  of the unit square covered when the atlas is in it).

For each mesh (default g1_kitten, g0_bunny_closed, g4_fertility and disk_hand from
../shared/meshes; the bunny takes minutes in xatlas, `--skip-slow` leaves it out) it
runs `xatlas.Atlas().add_mesh(V, F); generate(); get_mesh(0)` (what
`xatlas.parametrize(V, F)` does, plus reading the atlas's size and chart count), timed
as a whole, writes the result as OBJ to `--out` (v in input order, vt, f v/t), and with
`--beltrami BIN` runs `BIN atlas MESH -o OUT/NAME.beltrami.obj` timed as a process;
`--ours PATTERN` measures existing files instead ({name} is the mesh's stem). It prints
a markdown table, then per row the atlas's size in texels and the other figures.

Two things about xatlas's output. Its uvs are texel positions divided by the atlas's
width and height, which differ by a few per cent: the table measures the uvs as written,
the notes also give the L2 stretch in texels (square pixels). And its charts can come out
mirrored, for two reasons in its source: `ChartOptions.fix_winding` (off by default) is
what makes a chart's winding agree with the faces', and the packer's 90-degree "rotation"
of a chart (`PackOptions.rotate_charts`, on by default) swaps u and v, a reflection.
`--unmirrored` adds a row with the first on and the second off. Faces whose 3D area is at
most FLT_EPSILON (absolute) it leaves out of every chart with their corners at uv (0, 0):
they appear here as degenerate uv faces, and as small charts of their own.

`--measure FILE.obj [--mesh-file MESH.obj]` only measures one OBJ with vt and prints the
measure as JSON. Without the mesh the file's own vertices connect the faces, so a file
that repeats its vertices along the seams has no seams (a warning says so); with it the
3D positions and faces are the mesh's (the file's faces in the same order).

It installs numpy, scipy and xatlas into the peers' virtual environment (see
peer_scripts.py) and re-runs itself there. It is not part of CI. Usage (from the
repository root):

    python3 benches/peers/atlas_compare.py [--skip-slow] [--mesh g1_kitten ...]
        [--beltrami target/release/beltrami] [--unmirrored] [--json FILE]
    python3 benches/peers/atlas_compare.py --measure OUT.obj --mesh-file MESH.obj
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import time
from pathlib import Path

from peer_scripts import bootstrap

ROOT = Path(__file__).resolve().parents[2]
REQUIREMENTS = ["xatlas", "numpy", "scipy"]
DEFAULT_MESHES = ["g1_kitten", "g0_bunny_closed", "g4_fertility", "disk_hand"]
SLOW = {"g0_bunny_closed"}
CANDIDATE_CAP = 10**7
SHRINK = 1e-7
TOUCH = 1e-9


def read_obj_uv(path):
    """Positions (n, 3), triangles (m, 3), uvs (k, 2) and per-corner uv indices (m, 3)
    of an OBJ: `v`, `vt` and `f` lines with `v`, `v/t`, `v/t/n` or `v//n` corners
    (1-based or negative), polygons fanned as (0, i, i + 1). A corner without a uv gets
    -1."""
    import numpy as np

    positions, uvs, faces, corners = [], [], [], []
    with open(path) as f:
        for line in f:
            parts = line.split()
            if not parts:
                continue
            if parts[0] == "v":
                positions.append([float(t) for t in parts[1:4]])
            elif parts[0] == "vt":
                uvs.append([float(t) for t in parts[1:3]])
            elif parts[0] == "f":
                vs, ts = [], []
                for token in parts[1:]:
                    fields = token.split("/")
                    v = int(fields[0])
                    vs.append(v - 1 if v > 0 else len(positions) + v)
                    if len(fields) > 1 and fields[1]:
                        t = int(fields[1])
                        ts.append(t - 1 if t > 0 else len(uvs) + t)
                    else:
                        ts.append(-1)
                for i in range(1, len(vs) - 1):
                    faces.append([vs[0], vs[i], vs[i + 1]])
                    corners.append([ts[0], ts[i], ts[i + 1]])
    return (
        np.array(positions, dtype=np.float64).reshape(-1, 3),
        np.array(faces, dtype=np.int64).reshape(-1, 3),
        np.array(uvs, dtype=np.float64).reshape(-1, 2),
        np.array(corners, dtype=np.int64).reshape(-1, 3),
    )


def write_obj_uv(path, V, F, UV, FUV) -> None:
    with open(path, "w") as f:
        for x, y, z in V.tolist():
            f.write(f"v {x!r} {y!r} {z!r}\n")
        for u, v in UV.tolist():
            f.write(f"vt {u!r} {v!r}\n")
        for (a, b, c), (s, t, r) in zip(F.tolist(), FUV.tolist()):
            f.write(f"f {a + 1}/{s + 1} {b + 1}/{t + 1} {c + 1}/{r + 1}\n")


def _charts_and_seams(V, F, FUV):
    """Chart label per face, seam length, total edge length, misoriented edges."""
    import numpy as np
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    m = len(F)
    a = F.reshape(-1)  # half-edge k of face k // 3 runs from corner k % 3 ...
    b = F[:, [1, 2, 0]].reshape(-1)  # ... to the next corner
    ua = FUV.reshape(-1)
    ub = FUV[:, [1, 2, 0]].reshape(-1)
    face = np.repeat(np.arange(m), 3)
    swap = a > b
    lo, hi = np.where(swap, b, a), np.where(swap, a, b)
    ulo, uhi = np.where(swap, ub, ua), np.where(swap, ua, ub)

    # Half-edges sorted by (edge, uv at its lower vertex, uv at its upper vertex).
    order = np.lexsort((uhi, ulo, hi, lo))
    lo, hi, ulo, uhi, face, swap = (x[order] for x in (lo, hi, ulo, uhi, face, swap))
    same_edge = (lo[1:] == lo[:-1]) & (hi[1:] == hi[:-1])
    same_uv = same_edge & (ulo[1:] == ulo[:-1]) & (uhi[1:] == uhi[:-1])
    joined = coo_matrix(
        (np.ones(int(same_uv.sum())), (face[:-1][same_uv], face[1:][same_uv])), shape=(m, m)
    )
    count, label = connected_components(joined, directed=False)

    # Per undirected edge: how many half-edges, whether their uv pairs differ.
    starts = np.r_[0, np.nonzero(~same_edge)[0] + 1]
    sizes = np.diff(np.r_[starts, len(lo)])
    uv_changes = np.add.reduceat(np.r_[0, (same_edge & ~same_uv).astype(np.int64)], starts)
    length = np.linalg.norm(V[hi[starts]] - V[lo[starts]], axis=1)
    seam = (sizes >= 2) & (uv_changes > 0)
    # Two faces of a consistently oriented mesh run along a shared edge in opposite ways.
    pair = sizes == 2
    misoriented = int((swap[starts[pair]] == swap[starts[pair] + 1]).sum())
    return count, label, float(length[seam].sum()), float(length.sum()), misoriented


def _sat_overlap(A, B):
    """Whether triangles A[i] and B[i] ((p, 3, 2) each, already shrunk) overlap by more
    than TOUCH (in uv units, set by the caller) on each of the six edge normals."""
    import numpy as np

    overlap = np.ones(len(A), dtype=bool)
    for T in (A, B):
        for k in range(3):
            edge = T[:, (k + 1) % 3] - T[:, k]
            axis = np.stack([-edge[:, 1], edge[:, 0]], axis=1)
            axis /= np.maximum(np.linalg.norm(axis, axis=1), 1e-300)[:, None]
            pa = np.einsum("pkd,pd->pk", A, axis)
            pb = np.einsum("pkd,pd->pk", B, axis)
            depth = np.minimum(pa.max(1), pb.max(1)) - np.maximum(pa.min(1), pb.min(1))
            overlap &= depth > _sat_overlap.tolerance
    return overlap


_sat_overlap.tolerance = 0.0


def _overlaps(P, keep):
    """Overlapping pairs among the uv triangles P[keep]: (count, capped, examples)."""
    import numpy as np

    ids = np.nonzero(keep)[0]
    if len(ids) < 2:
        return 0, False, []
    T = P[ids]
    lo, hi = T.min(1), T.max(1)
    origin = lo.min(0)
    span = float((hi.max(0) - origin).max())
    if span <= 0:
        return 0, False, []
    _sat_overlap.tolerance = TOUCH * span
    centroid = T.mean(1, keepdims=True)
    shrunk = centroid + (1.0 - SHRINK) * (T - centroid)

    # Buckets: about the mean triangle extent, at most ~2 sqrt(n) per side.
    n_side = int(min(math.ceil(span / max(float((hi - lo).max(1).mean()), 1e-300)),
                     math.ceil(2.0 * math.sqrt(len(ids)))))
    n_side = max(n_side, 1)
    h = span / n_side
    c0 = np.clip(((lo - origin) / h).astype(np.int64), 0, n_side - 1)
    c1 = np.clip(((hi - origin) / h).astype(np.int64), 0, n_side - 1)
    width = c1[:, 0] - c0[:, 0] + 1
    per_tri = width * (c1[:, 1] - c0[:, 1] + 1)
    tri = np.repeat(np.arange(len(ids)), per_tri)
    k = np.arange(len(tri)) - np.repeat(np.cumsum(per_tri) - per_tri, per_tri)
    cell = (c0[tri, 1] + k // width[tri]) * n_side + (c0[tri, 0] + k % width[tri])
    order = np.argsort(cell, kind="stable")
    cell, tri = cell[order], tri[order]
    group_start = np.r_[0, np.nonzero(cell[1:] != cell[:-1])[0] + 1]
    group_end = np.r_[group_start[1:], len(cell)]
    end_of = np.repeat(group_end, group_end - group_start)
    partners = end_of - np.arange(len(cell)) - 1  # later entries of the same bucket
    total = int(partners.sum())
    capped = total > CANDIDATE_CAP
    if capped:
        upto = np.searchsorted(np.cumsum(partners), CANDIDATE_CAP, side="right")
        partners = partners.copy()
        partners[upto:] = 0

    count, examples = 0, []
    entry = np.arange(len(cell))
    chunk_pairs = 2_000_000
    bounds = np.cumsum(partners)
    first_entry = 0
    while first_entry < len(cell):
        start_pairs = bounds[first_entry - 1] if first_entry else 0
        last_entry = int(np.searchsorted(bounds, start_pairs + chunk_pairs, side="right"))
        last_entry = max(last_entry, first_entry + 1)
        e = entry[first_entry:last_entry]
        p = partners[first_entry:last_entry]
        first_entry = last_entry
        if p.sum() == 0:
            continue
        i = np.repeat(e, p)
        j = i + 1 + (np.arange(len(i)) - np.repeat(np.cumsum(p) - p, p))
        a, b = tri[i], tri[j]
        # Boxes meet, and this bucket holds the lower-left corner of their intersection
        # (so that each pair is tested once).
        corner = np.maximum(lo[a], lo[b])
        meet = (corner <= np.minimum(hi[a], hi[b])).all(1)
        cc = np.clip(((corner - origin) / h).astype(np.int64), 0, n_side - 1)
        mine = meet & (cc[:, 1] * n_side + cc[:, 0] == cell[i])
        a, b = a[mine], b[mine]
        hit = _sat_overlap(shrunk[a], shrunk[b])
        count += int(hit.sum())
        if len(examples) < 5 and hit.any():
            for x, y in zip(a[hit][:5].tolist(), b[hit][:5].tolist()):
                examples.append(sorted([int(ids[x]), int(ids[y])]))
    return count, capped, examples[:5]


def stretch(V, F, UV, FUV, keep=None):
    """Sander et al. 2001's L2 and Linf stretch of the atlas over the faces `keep` (by
    default those whose uv area is not degenerate), normalized to equal total uv and
    surface areas (module docs)."""
    import numpy as np

    q = np.asarray(V, dtype=np.float64)[F]
    p = np.asarray(UV, dtype=np.float64)[FUV]
    if keep is None:
        e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
        area = np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
        keep = area > 1e-14 * area.sum()
    q, p = q[keep], p[keep]
    A3 = 0.5 * np.linalg.norm(np.cross(q[:, 1] - q[:, 0], q[:, 2] - q[:, 0]), axis=1)
    s, t = p[..., 0], p[..., 1]
    twice = ((s[:, 1] - s[:, 0]) * (t[:, 2] - t[:, 0]) - (s[:, 2] - s[:, 0]) * (t[:, 1] - t[:, 0]))
    # The partial derivatives of S (uv -> 3D), affine on each face.
    Ss = (q[:, 0] * (t[:, 1] - t[:, 2])[:, None] + q[:, 1] * (t[:, 2] - t[:, 0])[:, None]
          + q[:, 2] * (t[:, 0] - t[:, 1])[:, None]) / twice[:, None]
    St = (q[:, 0] * (s[:, 2] - s[:, 1])[:, None] + q[:, 1] * (s[:, 0] - s[:, 2])[:, None]
          + q[:, 2] * (s[:, 1] - s[:, 0])[:, None]) / twice[:, None]
    a, b, c = (Ss * Ss).sum(1), (Ss * St).sum(1), (St * St).sum(1)
    big = np.sqrt(np.maximum(0.5 * (a + c + np.sqrt((a - c) ** 2 + 4 * b * b)), 0.0))
    sum2, sum3 = float(np.abs(0.5 * twice).sum()), float(A3.sum())
    if sum3 <= 0 or len(big) == 0:
        return float("nan"), float("nan")
    scale = math.sqrt(sum2 / sum3)
    l2 = math.sqrt(float(((a + c) / 2 * A3).sum()) / sum3) * scale
    return l2, float(big.max()) * scale


def measure(V, F, UV, FUV) -> dict:
    """The measure of an atlas (module docs)."""
    import numpy as np

    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    UV = np.asarray(UV, dtype=np.float64)
    FUV = np.asarray(FUV, dtype=np.int64)
    if F.shape != FUV.shape:
        raise ValueError("F and FUV differ in shape")
    if (FUV < 0).any() or (FUV >= len(UV)).any():
        raise ValueError("a face corner has no (valid) uv")
    m = len(F)
    q = V[F]
    p = UV[FUV]
    A3 = 0.5 * np.linalg.norm(np.cross(q[:, 1] - q[:, 0], q[:, 2] - q[:, 0]), axis=1)
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    A2 = 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])  # signed
    degenerate = np.abs(A2) <= 1e-14 * np.abs(A2).sum()
    ok = ~degenerate

    count, label, seam_length, edge_length, misoriented = _charts_and_seams(V, F, FUV)
    chart_area = np.bincount(label, weights=np.where(ok, A2, 0.0), minlength=count)
    mirrored = int((chart_area < 0).sum())
    flipped = ok & (np.sign(A2) != np.sign(chart_area[label])) & (chart_area[label] != 0)

    l2, linf = stretch(V, F, UV, FUV, ok)
    sum2, sum3 = float(np.abs(A2[ok]).sum()), float(A3[ok].sum())
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.abs(A2[ok]) * (sum3 / sum2) / A3[ok]
        log_ratio = np.abs(np.log(ratio))
    finite = np.isfinite(log_ratio)
    area_distortion = float((log_ratio[finite] * A3[ok][finite]).sum() / A3[ok][finite].sum())

    pairs, capped, examples = _overlaps(p, ok)
    used = UV[np.unique(FUV)]
    return {
        "faces": m,
        "charts": int(count),
        "l2_stretch": l2,
        "linf_stretch": linf,
        "seam_length": seam_length,
        "seam_fraction": seam_length / edge_length if edge_length > 0 else 0.0,
        "mirrored_charts": mirrored,
        "flipped_faces": int(flipped.sum()),
        "degenerate_uv_faces": int(degenerate.sum()),
        "overlapping_pairs": pairs,
        "overlap_capped": capped,
        "overlap_examples": examples,
        "area_distortion": area_distortion,
        "in_unit_square": bool(((used >= -1e-12) & (used <= 1 + 1e-12)).all()),
        "uv_area": sum2,
        "misoriented_edges": misoriented,
    }


def on_mesh(mesh_V, mesh_F, V, F, UV, FUV):
    """The 3D positions and faces to measure an output (V, F, UV, FUV) of the mesh
    (mesh_V, mesh_F) with: the mesh's when the output has the same faces in the same
    order with the same corner positions (a file may split its vertices along seams),
    otherwise the output's own with equal positions welded."""
    import numpy as np

    diagonal = float(np.linalg.norm(mesh_V.max(0) - mesh_V.min(0)))
    if len(F) == len(mesh_F):
        if np.abs(V[F] - mesh_V[mesh_F]).max() <= 1e-6 * diagonal:
            return mesh_V, mesh_F
    print("warning: the output's faces are not the mesh's; welding equal positions",
          file=sys.stderr)
    welded, inverse = np.unique(V, axis=0, return_inverse=True)
    return welded, inverse.reshape(-1)[F]


def run_xatlas(V, F, unmirrored=False):
    """xatlas with its default options, or with `fix_winding` on and `rotate_charts` off
    (`unmirrored`): (uv, per-corner uv indices, faces by input vertex, seconds, info)."""
    import numpy as np
    import xatlas

    positions = np.ascontiguousarray(V, dtype=np.float32)
    indices = np.ascontiguousarray(F, dtype=np.uint32)
    options = xatlas.ChartOptions()
    packing = xatlas.PackOptions()
    if unmirrored:
        options.fix_winding = True
        packing.rotate_charts = False
    start = time.perf_counter()
    atlas = xatlas.Atlas()
    atlas.add_mesh(positions, indices)
    atlas.generate(chart_options=options, pack_options=packing)
    vmapping, out_indices, uvs = atlas.get_mesh(0)
    seconds = time.perf_counter() - start
    FUV = out_indices.astype(np.int64)
    info = {"width": int(atlas.width), "height": int(atlas.height),
            "xatlas_charts": int(atlas.chart_count)}
    return uvs.astype(np.float64), FUV, vmapping.astype(np.int64)[FUV], seconds, info


def table_row(mesh, method, r, seconds) -> str:
    t = f"{seconds:.2f}" if seconds is not None else "-"
    pairs = f"{r['overlapping_pairs']}" + ("+" if r["overlap_capped"] else "")
    return (
        f"| {mesh} | {method} | {r['faces']} | {r['charts']} | {r['l2_stretch']:.4f} | "
        f"{r['linf_stretch']:.3f} | {100 * r['seam_fraction']:.2f} | {r['mirrored_charts']} | "
        f"{r['flipped_faces']} | {pairs} | {'yes' if r['in_unit_square'] else 'no'} | {t} |"
    )


def main() -> None:
    bootstrap(__file__, REQUIREMENTS, "import xatlas, numpy, scipy")
    import numpy as np

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--meshes", type=Path, default=ROOT.parent / "shared" / "meshes")
    parser.add_argument("--mesh", action="append", help="a mesh's name (repeatable)")
    parser.add_argument("--skip-slow", action="store_true", help="leave out g0_bunny_closed")
    parser.add_argument("--out", type=Path, default=Path("/tmp/atlas_compare"))
    parser.add_argument("--beltrami", type=Path, help="run `BIN atlas MESH -o OUT`")
    parser.add_argument("--beltrami-arg", action="append", default=[],
                        help="an extra argument of `beltrami atlas` (repeatable)")
    parser.add_argument("--ours", help="measure existing outputs: a path with {name}")
    parser.add_argument("--no-xatlas", action="store_true")
    parser.add_argument("--unmirrored", action="store_true",
                        help="also run xatlas with fix_winding on and rotate_charts off")
    parser.add_argument("--json", type=Path, help="write every measure here")
    parser.add_argument("--measure", type=Path, help="only measure this OBJ (with vt)")
    parser.add_argument("--mesh-file", type=Path, help="the mesh of --measure's OBJ")
    args = parser.parse_args()

    if args.measure is not None:
        V, F, UV, FUV = read_obj_uv(args.measure)
        if args.mesh_file is not None:
            mesh_V, mesh_F, _, _ = read_obj_uv(args.mesh_file)
            V, F = on_mesh(mesh_V, mesh_F, V, F, UV, FUV)
        elif len(np.unique(V, axis=0)) < len(V):
            print("warning: the file repeats positions (split along seams?): its seams are "
                  "found only with --mesh-file", file=sys.stderr)
        print(json.dumps(measure(V, F, UV, FUV), indent=2))
        return

    names = [n.removesuffix(".obj") for n in (args.mesh or DEFAULT_MESHES)]
    if args.skip_slow:
        names = [n for n in names if n not in SLOW]
    args.out.mkdir(parents=True, exist_ok=True)
    rows, notes, results = [], [], []
    for name in names:
        mesh_path = args.meshes / f"{name}.obj"
        V, F, _, _ = read_obj_uv(mesh_path)
        runs = [] if args.no_xatlas else [False] + ([True] if args.unmirrored else [])
        for fix in runs:
            method = "xatlas unmirrored" if fix else "xatlas"
            UV, FUV, F_out, seconds, info = run_xatlas(V, F, fix)
            if not np.array_equal(F_out, F):
                print(f"warning: {name}: xatlas reordered faces", file=sys.stderr)
            suffix = ".xatlas_unmirrored.obj" if fix else ".xatlas.obj"
            write_obj_uv(args.out / f"{name}{suffix}", V, F_out, UV, FUV)
            r = measure(V, F_out, UV, FUV)
            # xatlas divides u by the atlas's width and v by its height: in texels
            # (square pixels) the stretch can differ a little.
            texels = UV * [info["width"], info["height"]]
            l2_texels, _ = stretch(V, F_out, texels, FUV, None)
            r.update(info, l2_stretch_texels=l2_texels)
            rows.append(table_row(name, method, r, seconds))
            notes.append(f"{name} {method}: atlas {info['width']}x{info['height']} texels, "
                         f"xatlas counts {info['xatlas_charts']} charts, L2 in texels "
                         f"{l2_texels:.4f}, uv area "
                         f"{r['uv_area']:.3f}, area distortion {r['area_distortion']:.4f}, "
                         f"degenerate uv faces {r['degenerate_uv_faces']}, misoriented "
                         f"edges {r['misoriented_edges']}")
            results.append({"mesh": name, "method": method, "seconds": seconds, **r})
            print(rows[-1], file=sys.stderr)
        outputs = []
        if args.beltrami is not None:
            out = args.out / f"{name}.beltrami.obj"
            command = [str(args.beltrami), "atlas", str(mesh_path), "-o", str(out),
                       *args.beltrami_arg]
            start = time.perf_counter()
            done = subprocess.run(command, capture_output=True, text=True)
            seconds = time.perf_counter() - start
            if done.returncode != 0:
                print(f"{' '.join(command)} failed:\n{done.stderr}", file=sys.stderr)
            else:
                outputs.append(("beltrami atlas", out, seconds))
        if args.ours is not None:
            path = Path(args.ours.format(name=name))
            if path.exists():
                outputs.append((f"ours ({path.name})", path, None))
            else:
                print(f"no {path}", file=sys.stderr)
        for method, path, seconds in outputs:
            oV, oF, UV, FUV = read_obj_uv(path)
            try:
                mV, mF = on_mesh(V, F, oV, oF, UV, FUV)
                r = measure(mV, mF, UV, FUV)
            except ValueError as error:
                print(f"{path}: {error}", file=sys.stderr)
                continue
            rows.append(table_row(name, method, r, seconds))
            notes.append(f"{name} {method}: uv area {r['uv_area']:.3f}, area distortion "
                         f"{r['area_distortion']:.4f}, degenerate uv faces "
                         f"{r['degenerate_uv_faces']}, misoriented edges "
                         f"{r['misoriented_edges']}")
            results.append({"mesh": name, "method": method, "seconds": seconds, **r})

    print("| mesh | method | faces | charts | L2 | Linf | seams % | mirrored charts | "
          "flipped faces | overlap pairs | in [0,1]^2 | time s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for row in rows:
        print(row)
    print()
    for note in notes:
        print(f"- {note}")
    if args.json is not None:
        args.json.write_text(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
