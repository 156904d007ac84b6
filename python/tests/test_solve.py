"""``beltrami.solve``: any registered solver by name, the same maps as the named calls,
and the solver's own refusals."""

import numpy as np
import pytest

import beltrami
from conftest import MESHES


@pytest.fixture(scope="module")
def disk():
    return beltrami.read_mesh(MESHES / "disk_hemisphere.obj")


def test_every_registered_solver_is_reachable_by_name(disk):
    V, F = disk
    names = [s["name"] for s in beltrami.solvers()]
    assert "qc-iteration" in names and "lscm" in names
    for name in names:
        try:
            beltrami.solve(name, V, F)
        except beltrami.BeltramiError as error:
            # A refusal of this problem by the solver itself, never an unknown name.
            assert "no solver named" not in str(error), name


def test_the_same_maps_as_the_named_calls(disk):
    V, F = disk
    assert np.array_equal(beltrami.solve("lscm", V, F, boundary="free"), beltrami.lscm(V, F))
    flow = beltrami.solve("beltrami-flow", V, F, target="disk",
                          options={"tolerance": 1e-6, "max-iters": 200})
    assert np.array_equal(flow, beltrami.beltrami_flow(V, F, target="disk"))
    UV, report = beltrami.solve("lsqc", V * [1, 1, 0], F, mu_expr="0.3", boundary="free",
                                info=True)
    assert np.allclose(beltrami.beltrami_coefficient(V * [1, 1, 0], F, UV), 0.3)
    assert report["solver"] == "lsqc"


def test_an_unknown_name_and_a_refused_target_are_typed_errors(disk):
    V, F = disk
    with pytest.raises(beltrami.OptionError, match="no solver named `nosuch`; available: .*qc-iteration"):
        beltrami.solve("nosuch", V, F)
    with pytest.raises(beltrami.UnsupportedError, match="tutte"):
        beltrami.solve("tutte", V, F, target="sphere")


def test_a_remeshing_by_name_is_refused_before_any_work(disk):
    # `solve` returns maps; the remeshing (here to ten million vertices, which would
    # take minutes) makes a new mesh and is refused at once, pointing at its calls.
    V, F = disk
    with pytest.raises(beltrami.SolverError, match="beltrami.remesh"):
        beltrami.solve("remesh", V, F, options={"vertices": 10_000_000})


def test_a_new_solver_is_reached_without_edits_of_the_python_package(disk):
    # `affine` is one folder under plugins/ and one registry line (docs/adding-a-solver.md).
    V, F = disk
    V = V * [1, 1, 0]
    assert "affine" in [s["name"] for s in beltrami.solvers()]
    UV, report = beltrami.solve("affine", V, F, mu_expr="0.3+0.4i", boundary="free", info=True)
    assert report["solver"] == "affine"
    assert np.allclose(np.abs(beltrami.beltrami_coefficient(V, F, UV)), 0.5, atol=1e-12)


def test_the_solver_chooses_the_goal_and_meaningless_words_are_refused(disk):
    V, F = disk
    flat = V * [1, 1, 0]
    # No goal given: the extremal solver computes the extremal map of the boundary
    # values, here those of the stretch x -> 2x, which is its own extremal map:
    # f = 2x + iy = 1.5 z + 0.5 conj(z), mu = 1/3 on every face.
    stretched = flat[:, :2] * [2.0, 1.0]
    UV = beltrami.solve("extremal", flat, F, boundary="given", boundary_map=stretched)
    mu = beltrami.beltrami_coefficient(flat, F, UV)
    assert np.allclose(mu, 1.0 / 3.0, atol=1e-6)
    # A boundary condition off the plane is refused, named in Python's words.
    with pytest.raises(beltrami.OptionError, match=r"boundary is the boundary condition of target='plane'"):
        beltrami.solve("beltrami-flow", V, F, target="disk", boundary="keep")
    with pytest.raises(beltrami.OptionError, match=r"free_radius"):
        beltrami.beltrami_flow(V, F, target="disk", free_radius=True)
