"""Every call against the ``beltrami`` command on the same mesh: the same map to 1e-9."""

import json

import numpy as np
import pytest

import beltrami
from conftest import MESHES, close


def uv_of(path):
    _, _, uv = beltrami.read_mesh(path, uv=True)
    assert uv is not None, f"{path} has no texture coordinates"
    return uv


def positions_of(path):
    return beltrami.read_mesh(path)[0]


def report_of(path):
    with open(path, encoding="utf-8") as f:
        return json.load(f)


@pytest.mark.parametrize(
    "solver,flags,kwargs",
    [
        ("tutte", [], {}),
        ("tutte", ["--boundary", "square", "--weights", "mean-value"], {"boundary": "square", "weights": "mean-value"}),
        ("harmonic", [], {}),
        ("lscm", [], {}),
        ("lscm", ["--pin", "v0", "--pin", "v700"], {"pins": [0, 700]}),
    ],
)
def test_initial_maps_match_param(cli, hemisphere, tmp_path, solver, flags, kwargs):
    out = tmp_path / "out.obj"
    cli("param", hemisphere, "--solver", solver, *flags, "-o", out)
    V, F = beltrami.read_mesh(hemisphere)
    uv = getattr(beltrami, solver)(V, F, **kwargs)
    assert uv.shape == (len(V), 2)
    close(uv, uv_of(out))


def test_sphere_map_matches_param(cli, tmp_path):
    out = tmp_path / "out.obj"
    cli("param", MESHES / "spot.obj", "--solver", "sphere", "-o", out)
    V, F = beltrami.read_mesh(MESHES / "spot.obj")
    W, report = beltrami.sphere_map(V, F, info=True)
    close(W, positions_of(out))
    close(np.linalg.norm(W, axis=1), np.ones(len(W)), 1e-12)
    assert report["flipped"] == 0


def test_lsqc_matches_qc_with_an_expression_and_a_field(cli, generated, tmp_path):
    disk = generated("disk", 3)
    V, F = beltrami.read_mesh(disk)
    out = tmp_path / "expr.obj"
    cli("qc", disk, "--mu-expr", "0.3*z", "-o", out)
    close(beltrami.lsqc(V, F, mu_expr="0.3*z"), uv_of(out))

    mu = 0.25 * np.exp(1j * np.arange(len(F)) / 7.0)
    field = tmp_path / "mu.txt"
    field.write_text(
        f"# mu frame=global faces={len(F)}\n" + "".join(f"{float(z.real)!r} {float(z.imag)!r}\n" for z in mu)
    )
    out = tmp_path / "field.obj"
    cli("qc", disk, "--mu", field, "--boundary", "keep", "-o", out, "--report", tmp_path / "r.json")
    uv, report = beltrami.lsqc(V, F, mu=mu, boundary="keep", info=True)
    close(uv, uv_of(out))
    assert report["mu_error"]["rms"] == pytest.approx(report_of(tmp_path / "r.json")["mu_error"]["rms"], abs=1e-12)


def test_lsqc_into_space_matches_qc(cli, hemisphere, tmp_path):
    out = tmp_path / "out.obj"
    cli("qc", hemisphere, "--target", "space", "--boundary", "given", "--boundary-map", hemisphere,
        "--conformal", "-o", out)
    V, F = beltrami.read_mesh(hemisphere)
    X = beltrami.lsqc(V, F, target="space", boundary_map=V)
    close(X, positions_of(out))
    # The area constraint, with a boundary stretched in x.
    stretched = V * np.array([1.3, 1.0, 1.0])
    moved = tmp_path / "stretched.obj"
    beltrami.write_mesh(moved, stretched, F)
    cli("qc", hemisphere, "--target", "space", "--boundary", "given", "--boundary-map", moved,
        "--conformal", "--area-constraint", "-o", out)
    X = beltrami.lsqc(V, F, target="space", boundary_map=stretched, area_constraint=True)
    close(X, positions_of(out))
    assert np.abs(X - beltrami.lsqc(V, F, target="space", boundary_map=stretched)).max() > 1e-6


@pytest.mark.parametrize(
    "flags,kwargs",
    [
        (["--target", "disk", "--conformal"], {"target": "disk"}),
        (["--target", "disk", "--conformal", "--p", "4", "--max-iters", "5"], {"target": "disk", "p": 4, "max_iters": 5}),
    ],
)
def test_beltrami_flow_matches_qc(cli, hemisphere, tmp_path, flags, kwargs):
    out = tmp_path / "out.obj"
    cli("qc", hemisphere, "--solver", "beltrami-flow", *flags, "-o", out)
    V, F = beltrami.read_mesh(hemisphere)
    close(beltrami.beltrami_flow(V, F, **kwargs), uv_of(out))


def test_beltrami_flow_onto_the_sphere_with_a_prescribed_mu_matches_qc(cli, generated, tmp_path):
    sphere = generated("sphere", 2)
    out = tmp_path / "out.obj"
    cli("qc", sphere, "--target", "sphere", "--mu-expr", "0.2", "-o", out)
    V, F = beltrami.read_mesh(sphere)
    close(beltrami.beltrami_flow(V, F, target="sphere", mu_expr="0.2"), positions_of(out))


def affine_boundary_problem(generated, tmp_path):
    """A disk and the boundary values of the affine map z + 0.2 conj(z): the extremal
    map is that affine map, k = 0.2."""
    disk = generated("disk", 3)
    V, F = beltrami.read_mesh(disk)
    z = V[:, 0] + 1j * V[:, 1]
    w = z + 0.2 * np.conj(z)
    target = np.stack([w.real, w.imag], axis=1)
    boundary = tmp_path / "boundary.obj"
    beltrami.write_mesh(boundary, V, F, uv=target)
    return disk, V, F, target, boundary


@pytest.mark.parametrize("call,solver", [("extremal", "extremal"), ("qc_iteration", "qc-iteration")])
def test_extremal_maps_match_qc_and_find_the_affine_map(cli, generated, tmp_path, call, solver):
    disk, V, F, target, boundary = affine_boundary_problem(generated, tmp_path)
    out = tmp_path / "out.obj"
    cli("qc", disk, "--solver", solver, "--boundary", "given", "--boundary-map", boundary, "-o", out)
    uv, report = getattr(beltrami, call)(V, F, target, info=True)
    close(uv, uv_of(out))
    assert report["k"] == pytest.approx(0.2, abs=1e-6)
    close(uv, target, 1e-6)


def test_extremal_start_map_and_quadratic_differential_match_qc(cli, generated, tmp_path):
    disk, V, F, target, boundary = affine_boundary_problem(generated, tmp_path)
    start = tmp_path / "start.obj"
    beltrami.write_mesh(start, V, F, uv=beltrami.tutte(V, F))
    out, qd = tmp_path / "out.obj", tmp_path / "qd.txt"
    cli("qc", disk, "--solver", "extremal", "--boundary", "given", "--boundary-map", boundary,
        "--init", start, "--qd", qd, "-o", out)
    uv, report = beltrami.extremal(V, F, target, init=beltrami.tutte(V, F), info=True)
    close(uv, uv_of(out))
    lines = qd.read_text().splitlines()[1:]
    phi = np.array([complex(float(a), float(b)) for a, b in (l.split() for l in lines)])
    close(report["quadratic_differential"], phi)


def test_circle_domain_matches_param_qcmc(cli, generated, tmp_path):
    annulus = generated("annulus", 2)
    out, r = tmp_path / "out.obj", tmp_path / "r.json"
    cli("param", annulus, "--solver", "qcmc", "-o", out, "--report", r)
    V, F = beltrami.read_mesh(annulus)
    uv, report = beltrami.circle_domain(V, F, info=True)
    close(uv, uv_of(out))
    assert [c["loop"] for c in report["circles"]] == [c["loop"] for c in report_of(r)["circles"]]


def test_register_matches_the_command_with_its_correspondence(cli, tmp_path):
    source, target = MESHES / "spot.obj", MESHES / "blob.obj"
    out, corr = tmp_path / "out.obj", tmp_path / "corr.txt"
    landmarks = tmp_path / "marks.txt"
    landmarks.write_text("v 0 0\n")
    cli("register", source, target, "--landmarks", landmarks, "--max-iters", "3",
        "--correspondence", corr, "-o", out)
    V, F = beltrami.read_mesh(source)
    TV, TF = beltrami.read_mesh(target)
    P, face, bary = beltrami.register(V, F, TV, TF, landmarks=[(0, 0)], max_iters=3)
    close(P, positions_of(out))
    rows = [l.split() for l in corr.read_text().splitlines()]
    np.testing.assert_array_equal(face, [int(r[0]) for r in rows])
    close(bary, np.array([[float(x) for x in r[1:]] for r in rows]))
    # The barycentric coordinates reproduce the positions on the target.
    close(np.einsum("ij,ijk->ik", bary, TV[TF[face]]), P, 1e-12)


def test_register_with_features_matches_the_command(cli, tmp_path):
    # A field per vertex (a file for the command, an array in Python) and the computed
    # mean curvature: the same map both ways, the fields' match reported.
    source, target = MESHES / "spot.obj", MESHES / "blob.obj"
    V, F = beltrami.read_mesh(source)
    TV, TF = beltrami.read_mesh(target)
    fs, ft = tmp_path / "fs.txt", tmp_path / "ft.txt"
    fs.write_text("".join(f"{float(z)!r}\n" for z in V[:, 2]))
    ft.write_text("".join(f"{float(z)!r}\n" for z in TV[:, 2]))
    landmarks = tmp_path / "marks.txt"
    landmarks.write_text("v 0 0\nv 700 300\nv 1500 900\n")
    out = tmp_path / "out.obj"
    cli("register", source, target, "--landmarks", landmarks, "--max-iters", "3",
        "--features", fs, ft, "-o", out)
    marks = [(0, 0), (700, 300), (1500, 900)]
    P, face, bary, info = beltrami.register(V, F, TV, TF, landmarks=marks, max_iters=3,
                                            features=(V[:, 2], TV[:, 2]), info=True)
    close(P, positions_of(out))
    assert any("features matched" in note for note in info["notes"])
    assert info["features"]["after"] <= info["features"]["before"]
    assert info["flipped"] == 0
    for (s, t) in marks:
        close(P[s], TV[t], 1e-12)
    out = tmp_path / "curvature.obj"
    cli("register", source, target, "--max-iters", "3", "--features", "mean-curvature",
        "mean-curvature", "-o", out)
    P = beltrami.register(V, F, TV, TF, max_iters=3, features=("mean-curvature", "mean-curvature"))[0]
    close(P, positions_of(out))
    with pytest.raises(beltrami.FieldError, match="3 values"):
        beltrami.register(V, F, TV, TF, features=([1.0, 2.0, 3.0], TV[:, 2]))
    with pytest.raises(beltrami.OptionError, match="neither mu nor p"):
        beltrami.register(V, F, TV, TF, p=4, features=(V[:, 2], TV[:, 2]))


def test_register_match_shape_matches_the_command(cli, tmp_path):
    # The shape matched both ways gives the same map, its distances reported.
    source, target = MESHES / "spot.obj", MESHES / "blob.obj"
    V, F = beltrami.read_mesh(source)
    TV, TF = beltrami.read_mesh(target)
    out = tmp_path / "out.obj"
    cli("register", source, target, "--max-iters", "3", "--match-shape", "-o", out)
    P, face, bary, info = beltrami.register(V, F, TV, TF, max_iters=3, match_shape=True,
                                            info=True)
    close(P, positions_of(out))
    assert info["shape"]["after"] < info["shape"]["before"]


def test_register_in_place_matches_the_command(cli, tmp_path):
    # The shape matched from the source where it is, both ways; without the shape
    # match the keyword is refused before any work.
    source, target = MESHES / "spot.obj", MESHES / "blob.obj"
    V, F = beltrami.read_mesh(source)
    TV, TF = beltrami.read_mesh(target)
    out = tmp_path / "out.obj"
    cli("register", source, target, "--max-iters", "3", "--match-shape", "--in-place", "-o", out)
    P, face, bary = beltrami.register(V, F, TV, TF, max_iters=3, match_shape=True, in_place=True)
    close(P, positions_of(out))
    with pytest.raises(beltrami.BeltramiError, match="match-shape"):
        beltrami.register(V, F, TV, TF, in_place=True)


def test_register_inverse_consistency_matches_the_command(cli, tmp_path):
    source, target = MESHES / "spot.obj", MESHES / "blob.obj"
    landmarks = tmp_path / "marks.txt"
    landmarks.write_text("v 0 0\nv 700 300\nv 1500 900\n")
    out, report = tmp_path / "out.obj", tmp_path / "r.json"
    cli("register", source, target, "--landmarks", landmarks, "--max-iters", "3",
        "--inverse-consistency", "--report", report, "-o", out)
    V, F = beltrami.read_mesh(source)
    TV, TF = beltrami.read_mesh(target)
    info = beltrami.register(V, F, TV, TF, landmarks=[(0, 0), (700, 300), (1500, 900)],
                             max_iters=3, inverse_consistency=True, info=True)[-1]
    want = report_of(report)["inverse_consistency"]
    got = info["inverse_consistency"]
    assert got["worst_vertex"] == want["worst_vertex"]
    for key in ("mean", "max", "relative_mean", "relative_max"):
        assert abs(got[key] - want[key]) <= 1e-9 * max(1.0, abs(want[key])), key
    with pytest.raises(beltrami.ConstraintError, match="line 1"):
        beltrami.register(V, F, TV, TF, landmarks=[(0, tuple(TV[0]))], inverse_consistency=True)


def test_register_of_a_multiply_connected_pair_matches_the_command(cli, generated, tmp_path):
    # Genus 0 with two boundary loops: the matched cut graphs of the initial map.
    source = generated("annulus", "1")
    target = generated("annulus", "2", "--inner", "0.3")
    out = tmp_path / "out.obj"
    cli("register", source, target, "--max-iters", "5", "-o", out)
    V, F = beltrami.read_mesh(source)
    TV, TF = beltrami.read_mesh(target)
    P, face, bary = beltrami.register(V, F, TV, TF, max_iters=5)
    close(P, positions_of(out))
    info = beltrami.register(V, F, TV, TF, max_iters=5, info=True)[-1]
    assert any("cut graphs" in note for note in info["notes"])
    assert info["flipped"] == 0


def test_beltrami_coefficient_and_distortion_match_the_command(cli, hemisphere, tmp_path):
    V, F = beltrami.read_mesh(hemisphere)
    uv = beltrami.tutte(V, F)
    mapped, per_face = tmp_path / "mapped.obj", tmp_path / "mu.txt"
    beltrami.write_mesh(mapped, V, F, uv=uv)
    run = cli("distortion", hemisphere, mapped, "--json", "--per-face", per_face)
    expected = json.loads(run.stdout)
    stats = beltrami.distortion(V, F, uv)
    for key in ("faces", "flipped", "mu_mean", "mu_max", "mu_std", "mu_l2", "frame"):
        assert stats[key] == pytest.approx(expected[key], abs=1e-12), key
    lines = per_face.read_text().splitlines()
    assert "frame=face" in lines[0]
    mu = np.array([complex(float(a), float(b)) for a, b in (l.split() for l in lines[1:])])
    close(beltrami.beltrami_coefficient(V, F, uv), mu)


def test_remesh_matches_the_command(cli, hemisphere, tmp_path):
    out, r = tmp_path / "out.obj", tmp_path / "r.json"
    cli("remesh", hemisphere, "--edge-length", "0.08", "-o", out, "--report", r)
    V, F = beltrami.read_mesh(hemisphere)
    V2, F2, report = beltrami.remesh(V, F, edge_length=0.08, info=True)
    W, G = beltrami.read_mesh(out)
    close(V2, W)
    np.testing.assert_array_equal(F2, G)
    assert report["min_angle"] == pytest.approx(report_of(r)["min_angle"], abs=1e-12)
    assert report["min_angle"] >= 20.0


def test_remesh_through_the_spherical_map_matches_the_command(cli, tmp_path):
    spot = MESHES / "spot.obj"
    out, r = tmp_path / "out.obj", tmp_path / "r.json"
    cli("remesh", spot, "--edge-length", "0.06", "--param", "sphere", "-o", out, "--report", r)
    V, F = beltrami.read_mesh(spot)
    V2, F2, report = beltrami.remesh(V, F, edge_length=0.06, param="sphere", info=True)
    W, G = beltrami.read_mesh(out)
    close(V2, W)
    np.testing.assert_array_equal(F2, G)
    assert report["opening"] == report_of(r)["opening"] == "two-charts"
    assert report["topology"] == "genus 0 and no boundary"


def test_remesh_in_place_matches_the_command(cli, tmp_path):
    spot = MESHES / "spot.obj"
    out, r = tmp_path / "out.obj", tmp_path / "r.json"
    cli("remesh", spot, "--method", "qc-angles", "-o", out, "--report", r)
    V, F = beltrami.read_mesh(spot)
    V2, report = beltrami.remesh_in_place(V, F, info=True)
    W, G = beltrami.read_mesh(out)
    close(V2, W)
    np.testing.assert_array_equal(F, G)
    assert report["after"]["min_angle"] == pytest.approx(report_of(r)["after"]["min_angle"], abs=1e-9)
    assert report["after"]["min_angle"] > report["before"]["min_angle"] + 5.0
    with pytest.raises(beltrami.OptionError, match="reference"):
        beltrami.remesh_in_place(V, F, reference="round")


def test_cut_to_disk_matches_the_command(cli, generated, tmp_path):
    torus = generated("torus1", 0)
    out = tmp_path / "out.obj"
    cli("cut", torus, "-o", out)
    V, F = beltrami.read_mesh(torus)
    V2, F2, original, report = beltrami.cut_to_disk(V, F, info=True)
    W, G = beltrami.read_mesh(out)
    close(V2, W, 0.0)
    np.testing.assert_array_equal(F2, G)
    close(V2, V[original], 0.0)
    assert report["genus"] == 1
    assert beltrami.mesh_info(V2, F2)["topology"] == "genus 0 and one boundary loop"


def test_read_and_write_round_trip(hemisphere, tmp_path):
    V, F = beltrami.read_mesh(hemisphere)
    uv = beltrami.lscm(V, F)
    for name in ("m.obj", "m.glb"):
        beltrami.write_mesh(tmp_path / name, V, F, uv=uv)
        W, G, back = beltrami.read_mesh(tmp_path / name, uv=True)
        close(W, V, 1e-6 if name.endswith("glb") else 0.0)
        np.testing.assert_array_equal(G, F)
        close(back, uv, 1e-6 if name.endswith("glb") else 0.0)


def test_the_catalog_lists_every_solver(cli):
    ours = beltrami.solvers()
    theirs = json.loads(cli("solvers", "--json").stdout)
    assert ours == theirs
    names = {s["name"] for s in ours}
    assert {"tutte", "harmonic", "lscm", "sphere", "lsqc", "beltrami-flow", "register", "qcmc",
            "extremal", "qc-iteration"} <= names


@pytest.mark.parametrize("name", ["disk_hemisphere.obj", "spot.obj"])
def test_mesh_info_matches_info(cli, name):
    expected = json.loads(cli("info", MESHES / name, "--json").stdout)
    info = beltrami.mesh_info(*beltrami.read_mesh(MESHES / name))
    for key in ("vertices", "faces", "edges", "components", "euler_characteristic", "genus"):
        assert info[key] == expected[key], key
    assert info["boundary_loops"] == len(expected["boundary_loops"])


def test_the_four_point_problem_matches_qc(cli, generated, tmp_path):
    disk = generated("disk", 4)
    V, F = beltrami.read_mesh(disk)
    info = beltrami.mesh_info(V, F)
    assert info["boundary_loops"] == 1
    angles = np.arctan2(V[:, 1], V[:, 0])
    on_circle = np.abs(np.hypot(V[:, 0], V[:, 1]) - 1.0) < 1e-9
    phi = np.pi / 6
    marks = []
    for j, to in enumerate([phi, np.pi - phi, np.pi + phi, 2 * np.pi - phi]):
        target = np.pi / 4 + j * np.pi / 2
        gap = np.abs(np.angle(np.exp(1j * (angles - target))))
        v = int(np.argmin(np.where(on_circle, gap, np.inf)))
        marks.append((v, (float(np.cos(to)), float(np.sin(to)))))
    path = tmp_path / "marks.txt"
    path.write_text("".join(f"p {v} {x!r} {y!r}\n" for v, (x, y) in marks))
    out, r = tmp_path / "out.obj", tmp_path / "r.json"
    cli("qc", disk, "--solver", "extremal", "--target", "disk", "--landmarks", path, "-o", out,
        "--report", r)
    uv, report = beltrami.extremal(V, F, landmarks=marks, info=True)
    close(uv, uv_of(out))
    assert report["k"] == pytest.approx(report_of(r)["k"], abs=1e-12)
    # The exact k of these points is 0.1225 (plugins/extremal/tests/four_point.rs).
    assert report["k"] == pytest.approx(0.1225, rel=0.03)


def test_lscm_takes_libigl_b_and_bc(hemisphere):
    V, F = beltrami.read_mesh(hemisphere)
    # The hemisphere pressed flat: a planar disk, whose own positions are a conformal
    # map. Pins at a similarity of their positions: LSCM gives that similarity exactly
    # (zero energy, the unique minimizer through the pins), with three pins or two.
    flat = V * [1.0, 1.0, 0.0]
    z = flat[:, 0] + 1j * flat[:, 1]
    moved = (0.6 - 0.8j) * 2 * z + (1 + 0.5j)
    b = np.array([0, 60, 700])
    bc = np.column_stack([moved[b].real, moved[b].imag])
    for k in (3, 2):
        UV = beltrami.lscm(flat, F, b[:k], bc[:k])
        np.testing.assert_allclose(UV[b[:k]], bc[:k], atol=1e-12)
        np.testing.assert_allclose(UV @ [1, 1j], moved, atol=1e-9)
    # On the curved surface every pin still lands exactly where asked.
    UV = beltrami.lscm(V, F, b, bc)
    np.testing.assert_allclose(UV[b], bc, atol=1e-12)
    with pytest.raises(beltrami.ConstraintError, match=r"bc has shape \(2, 2\); expected \(3, 2\)"):
        beltrami.lscm(V, F, b, bc[:2])
    with pytest.raises(beltrami.ConstraintError, match="bc row 1 is not finite"):
        beltrami.lscm(V, F, b[:2], [[0, 0], [np.nan, 1]])
    with pytest.raises(beltrami.OptionError, match="not both"):
        beltrami.lscm(V, F, b[:2], bc[:2], pins=[0, 1])


def test_components_each_and_largest_match_param(cli, hemisphere, tmp_path):
    V, F = beltrami.read_mesh(hemisphere)
    V2 = np.vstack([V, V * 0.5 + [3.0, 0.0, 0.0]])
    F2 = np.vstack([F, F + len(V)])
    path = tmp_path / "two.obj"
    beltrami.write_mesh(path, V2, F2)
    out = tmp_path / "out.obj"
    cli("param", path, "--solver", "lscm", "--components", "each", "-o", out)
    close(beltrami.lscm(V2, F2, components="each"), uv_of(out))
    with pytest.raises(beltrami.UnsupportedError, match="2 components"):
        beltrami.lscm(V2, F2)
    with pytest.raises(beltrami.OptionError, match="expected 'each'"):
        beltrami.lscm(V2, F2, components="all")
    # The largest alone (both have as many faces: the first of equals), NaN elsewhere.
    largest = tmp_path / "largest.obj"
    cli("param", path, "--solver", "lscm", "--components", "largest", "-o", largest)
    UV, report = beltrami.lscm(V2, F2, components="largest", info=True)
    close(UV[: len(V)], uv_of(largest))
    close(UV[: len(V)], beltrami.lscm(V, F))
    assert np.isnan(UV[len(V):]).all()
    assert any("largest of 2 components" in note for note in report["notes"])


def test_remesh_of_a_mesh_in_pieces_matches_the_command(cli, hemisphere, tmp_path):
    V, F = beltrami.read_mesh(hemisphere)
    spot_V, spot_F = beltrami.read_mesh(MESHES / "spot.obj")
    V2 = np.vstack([V, spot_V + [3.0, 0.0, 0.0]])
    F2 = np.vstack([F, spot_F + len(V)])
    path = tmp_path / "two.obj"
    beltrami.write_mesh(path, V2, F2)
    with pytest.raises(beltrami.UnsupportedError, match="2 components.*components='each'"):
        beltrami.remesh(V2, F2, edge_length=0.1)
    with pytest.raises(beltrami.OptionError, match="expected 'each'"):
        beltrami.remesh(V2, F2, edge_length=0.1, components="all")
    for which in ("each", "largest"):
        out, r = tmp_path / f"{which}.obj", tmp_path / f"{which}.json"
        cli("remesh", path, "--edge-length", "0.1", "--components", which, "-o", out, "--report", r)
        W, G, report = beltrami.remesh(V2, F2, edge_length=0.1, components=which, info=True)
        X, H = beltrami.read_mesh(out)
        close(W, X)
        np.testing.assert_array_equal(G, H)
        expected = report_of(r)
        for key in ("vertices", "faces", "input_faces", "opening", "parameterizer"):
            assert report[key] == expected[key], key
    # each: both pieces, listed in order; largest: spot alone (it has the most faces).
    assert [c["input_faces"] for c in report_of(tmp_path / "each.json")["components"]] == [len(F), len(spot_F)]
    assert report["input_faces"] == len(spot_F) > len(F)
    assert any("largest of 2 components" in note for note in report["notes"])


def test_atlas_matches_the_command(cli, tmp_path):
    spot = MESHES / "spot.obj"
    out, r = tmp_path / "out.obj", tmp_path / "r.json"
    cli("atlas", spot, "-o", out, "--report", r)
    V, F = beltrami.read_mesh(spot)
    UV, FUV, info = beltrami.atlas(V, F)
    lines = out.read_text().splitlines()
    vt = np.array([[float(x) for x in l.split()[1:3]] for l in lines if l.startswith("vt ")])
    f = [[[int(x) - 1 for x in c.split("/")] for c in l.split()[1:]] for l in lines if l.startswith("f ")]
    close(UV, vt)
    np.testing.assert_array_equal(FUV, np.array([[c[1] for c in face] for face in f]))
    np.testing.assert_array_equal(F, np.array([[c[0] for c in face] for face in f]))
    assert info["charts"] == report_of(r)["charts"]
    # Sander's L2 stretch recomputed here from the arrays agrees with the report.
    P, T = V[F], UV[FUV]
    a2 = (T[:, 1, 0] - T[:, 0, 0]) * (T[:, 2, 1] - T[:, 0, 1]) - (T[:, 1, 1] - T[:, 0, 1]) * (T[:, 2, 0] - T[:, 0, 0])
    assert (a2 > 0).all()
    ss = (P[:, 0] * (T[:, 1, 1] - T[:, 2, 1])[:, None] + P[:, 1] * (T[:, 2, 1] - T[:, 0, 1])[:, None] + P[:, 2] * (T[:, 0, 1] - T[:, 1, 1])[:, None]) / a2[:, None]
    st = (P[:, 0] * (T[:, 2, 0] - T[:, 1, 0])[:, None] + P[:, 1] * (T[:, 0, 0] - T[:, 2, 0])[:, None] + P[:, 2] * (T[:, 1, 0] - T[:, 0, 0])[:, None]) / a2[:, None]
    area = 0.5 * np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)
    l2 = np.sqrt(((ss**2).sum(1) + (st**2).sum(1)) / 2 @ area / area.sum()) * np.sqrt(0.5 * a2.sum() / area.sum())
    assert l2 == pytest.approx(info["stretch"]["l2"], rel=1e-9)
    assert l2 <= 1.1
    with pytest.raises(beltrami.OptionError, match="cones"):
        beltrami.atlas(V, F, cones="many")
    with pytest.raises(beltrami.OptionError, match="max-stretch"):
        beltrami.atlas(V, F, max_stretch=0.5)
    with pytest.raises(beltrami.OptionError, match="charts"):
        beltrami.atlas(V, F, charts=0)
    # charts=N is the command's --charts N.
    out6, r6 = tmp_path / "six.obj", tmp_path / "six.json"
    cli("atlas", spot, "-o", out6, "--report", r6, "--charts", "6")
    UV6, FUV6, info6 = beltrami.atlas(V, F, charts=6)
    assert info6["charts"] == report_of(r6)["charts"] >= 6
    assert info6["options"]["charts"] == 6
    lines = out6.read_text().splitlines()
    close(UV6, np.array([[float(x) for x in l.split()[1:3]] for l in lines if l.startswith("vt ")]))
