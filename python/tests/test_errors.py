"""A bad input per call: a typed exception whose message names the element, never a
crash; and the exception hierarchy."""

import os
import signal
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import beltrami
from conftest import MESHES


@pytest.fixture(scope="module")
def disk():
    return beltrami.read_mesh(MESHES / "disk_hemisphere.obj")


@pytest.fixture(scope="module")
def closed():
    return beltrami.read_mesh(MESHES / "spot.obj")


def test_the_hierarchy_derives_from_the_builtin_exceptions():
    assert issubclass(beltrami.MeshError, ValueError)
    assert issubclass(beltrami.MeshFileError, OSError)
    assert issubclass(beltrami.SolverError, RuntimeError)
    for name in ("MeshError", "MeshFileError", "OptionError", "ConstraintError", "FieldError",
                 "UnsupportedError", "SolverError"):
        assert issubclass(getattr(beltrami, name), beltrami.BeltramiError)


def test_tutte_names_a_non_finite_vertex(disk):
    V, F = disk
    V = V.copy()
    V[3, 1] = np.nan
    with pytest.raises(beltrami.MeshError, match=r"vertex 3 has a non-finite coordinate"):
        beltrami.tutte(V, F)


def test_harmonic_refuses_a_closed_mesh(closed):
    with pytest.raises(beltrami.UnsupportedError, match="harmonic"):
        beltrami.harmonic(*closed)


def test_advice_is_in_python_terms(closed):
    # The command line says "run `beltrami cut` first or use beltrami-flow".
    with pytest.raises(beltrami.UnsupportedError) as error:
        beltrami.lscm(*closed)
    message = str(error.value)
    assert "beltrami.cut_to_disk(V, F)" in message and "beltrami.beltrami_flow" in message, message
    assert "`beltrami cut`" not in message


def test_lscm_names_a_pin_off_the_mesh(disk):
    with pytest.raises(beltrami.ConstraintError, match=r"vertex 99999"):
        beltrami.lscm(*disk, pins=[0, 99999])


def test_sphere_map_refuses_a_disk(disk):
    with pytest.raises(beltrami.UnsupportedError, match="sphere"):
        beltrami.sphere_map(*disk)


def test_lsqc_names_a_face_with_mu_of_modulus_one(disk):
    V, F = disk
    mu = np.zeros(len(F), dtype=complex)
    mu[17] = 1.0
    with pytest.raises(beltrami.FieldError, match=r"face f17 has \|mu\| = 1"):
        beltrami.lsqc(V, F, mu=mu, mu_frame="face")


def test_lsqc_names_a_wrong_field_length(disk):
    V, F = disk
    with pytest.raises(beltrami.FieldError, match=rf"3 values for a mesh of {len(F)} faces"):
        beltrami.lsqc(V, F, mu=np.zeros(3, dtype=complex))


def test_beltrami_flow_refuses_an_unknown_target(disk):
    with pytest.raises(beltrami.OptionError, match="torus"):
        beltrami.beltrami_flow(*disk, target="torus")


def test_solver_options_are_checked_before_any_work(disk):
    with pytest.raises(beltrami.OptionError, match="tolerance"):
        beltrami.beltrami_flow(*disk, tolerance=-1.0)
    with pytest.raises(beltrami.OptionError, match="no-such-option"):
        beltrami.beltrami_flow(*disk, options={"no-such-option": 1})


def test_extremal_names_a_boundary_map_of_the_wrong_shape(disk):
    V, F = disk
    with pytest.raises(beltrami.ConstraintError, match=r"boundary_map has shape \(10, 2\)"):
        beltrami.extremal(V, F, np.zeros((10, 2)))


def test_qc_iteration_names_a_non_finite_row(disk):
    V, F = disk
    target = V[:, :2].copy()
    target[5] = np.inf
    with pytest.raises(beltrami.ConstraintError, match=r"row 5"):
        beltrami.qc_iteration(V, F, target)


def test_circle_domain_refuses_a_closed_mesh(closed):
    with pytest.raises(beltrami.UnsupportedError, match="qcmc"):
        beltrami.circle_domain(*closed)


def test_register_refuses_meshes_of_different_topology(disk, closed):
    with pytest.raises(beltrami.UnsupportedError):
        beltrami.register(*disk, *closed)


def test_register_names_a_landmarks_line(disk):
    with pytest.raises(beltrami.ConstraintError, match=r"landmarks:1"):
        beltrami.register(*disk, *disk, landmarks=[(0, 10**6)])


def test_beltrami_coefficient_names_a_wrong_row_count(disk):
    V, F = disk
    with pytest.raises(beltrami.ConstraintError, match=r"the map has shape \(4, 2\)"):
        beltrami.beltrami_coefficient(V, F, np.zeros((4, 2)))


def test_distortion_names_a_face_index_out_of_range(disk):
    V, F = disk
    F = F.copy()
    F[7, 2] = len(V) + 5
    with pytest.raises(beltrami.MeshError, match=rf"face 7 refers to vertex {len(V) + 5}"):
        beltrami.distortion(V, F, V[:, :2])


def test_negative_indices_and_bad_shapes_are_mesh_errors(disk):
    V, F = disk
    with pytest.raises(beltrami.MeshError, match=r"face 0 refers to vertex -1"):
        beltrami.mesh_info(V, np.array([[-1, 1, 2]]))
    with pytest.raises(beltrami.MeshError, match=r"\(n, 3\)"):
        beltrami.mesh_info(np.zeros((3, 5)), F)
    with pytest.raises(beltrami.MeshError, match="integer"):
        beltrami.mesh_info(V, F.astype(float))
    huge = F.astype(np.uint64)
    huge[5, 1] = 2**63
    with pytest.raises(beltrami.MeshError, match=r"face 5 refers to vertex 9223372036854775808"):
        beltrami.mesh_info(V, huge)


def test_remesh_needs_a_resolution(disk):
    with pytest.raises(beltrami.OptionError, match="edge_length"):
        beltrami.remesh(*disk)
    with pytest.raises(beltrami.OptionError, match="min"):
        beltrami.remesh(*disk, edge_length=0.1, min_angle=50.0)
    with pytest.raises(beltrami.OptionError, match="feature-tolerance"):
        beltrami.remesh(*disk, edge_length=0.1, feature_tolerance=0.0)
    # Sizes that would make too many vertices: refused before any work (they ran past
    # a minute).
    with pytest.raises(beltrami.OptionError, match="more than the most allowed"):
        beltrami.remesh(*disk, vertices=10**12)
    with pytest.raises(beltrami.OptionError, match=r"\(100, option `max-vertices`\)"):
        beltrami.remesh(*disk, edge_length=1e-3, max_vertices=100)


def test_cut_to_disk_refuses_a_closed_genus_0_mesh(closed):
    with pytest.raises(beltrami.UnsupportedError):
        beltrami.cut_to_disk(*closed)


def test_files(tmp_path, disk):
    with pytest.raises(beltrami.MeshFileError, match="missing.obj"):
        beltrami.read_mesh(tmp_path / "missing.obj")
    with pytest.raises(beltrami.MeshFileError, match="unknown output format"):
        beltrami.write_mesh(tmp_path / "mesh.xyz", *disk)
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n")
    with pytest.raises(beltrami.MeshFileError, match="7"):
        beltrami.read_mesh(bad)


def test_the_gil_is_released_during_a_solve():
    V, F = beltrami.read_mesh(MESHES / "disk_hemisphere.obj")
    ticks = []
    done = threading.Event()

    def tick():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    thread = threading.Thread(target=tick)
    thread.start()
    try:
        start = time.perf_counter()
        beltrami.beltrami_flow(V, F, p=4, max_iters=30)
        end = time.perf_counter()
    finally:
        done.set()
        thread.join()
    during = [t for t in ticks if start < t < end]
    # A thread that could not take the GIL would not tick while the solve runs.
    assert len(during) > 0.25 * (end - start) / 0.001 * 0.1, (len(during), end - start)


def test_ctrl_c_stops_a_long_solve(tmp_path):
    script = tmp_path / "long.py"
    script.write_text(textwrap.dedent(f"""
        import signal, sys, beltrami, numpy as np
        # Python leaves SIGINT ignored when it starts so (a background job of a shell
        # without job control): the Ctrl-C of a user's terminal is what is tested.
        signal.signal(signal.SIGINT, signal.default_int_handler)
        V, F = beltrami.read_mesh({str(MESHES / "disk_hemisphere.obj")!r})
        # About 41K vertices: the flow towards a prescribed mu below takes about 8 s to
        # stall (a conformal goal settles within a second from its boundary-first start).
        V, F = beltrami.remesh(V, F, edge_length=0.012)
        print("start", flush=True)
        try:
            beltrami.beltrami_flow(V, F, mu=np.full(len(F), 0.5 + 0j), mu_frame="face",
                                   tolerance=1e-300, max_iters=100000,
                                   options={{"min-step": 1e-300}})
        except KeyboardInterrupt:
            print("interrupted", flush=True)
            sys.exit(3)
        print("finished", flush=True)
    """))
    proc = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "start"
    time.sleep(1.0)
    proc.send_signal(signal.SIGINT)
    try:
        out, _ = proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        proc.kill()
        raise AssertionError("the solve did not stop within 30 s of Ctrl-C")
    assert proc.returncode == 3, out
    assert "interrupted" in out


def test_a_progress_callback_sees_every_step_and_can_stop_the_solve(disk):
    steps = []
    beltrami.beltrami_flow(*disk, p=4, max_iters=5, progress=lambda *a: steps.append(a))
    assert steps and all(isinstance(s[0], str) for s in steps)

    def stop(*_):
        raise RuntimeError("enough")

    with pytest.raises(RuntimeError, match="enough"):
        beltrami.beltrami_flow(*disk, p=4, max_iters=50, progress=stop)


def test_extremal_needs_a_boundary_map_or_landmarks(disk):
    with pytest.raises(beltrami.OptionError, match="one of the two"):
        beltrami.extremal(*disk)
    with pytest.raises(beltrami.UnsupportedError, match="v0 is not on the boundary"):
        beltrami.extremal(*disk, landmarks=[(0, (1.0, 0.0))])


def test_every_bad_argument_is_a_beltrami_error(disk):
    V, F = disk
    with pytest.raises(beltrami.OptionError, match=r"vertices=-1: give a whole number of vertices"):
        beltrami.remesh(V, F, vertices=-1)
    with pytest.raises(beltrami.OptionError, match=r"max_vertices=2.5"):
        beltrami.remesh(V, F, vertices=100, max_vertices=2.5)
    with pytest.raises(beltrami.ConstraintError, match=r"landmark 0: expected \(source vertex.*got \('a', 'b'\)"):
        beltrami.register(V, F, V, F, landmarks=[("a", "b")])
    with pytest.raises(beltrami.ConstraintError, match=r"landmark 0: expected \(vertex, \(x, y\)\), got \('a', \(0, 1\)\)"):
        beltrami.extremal(V, F, landmarks=[("a", (0, 1))])
    with pytest.raises(beltrami.OptionError, match=r"takes a whole number from \d+ to \d+, got `-1`"):
        beltrami.beltrami_flow(V, F, max_iters=-1)
