"""PLY, STL and OFF files written by trimesh read by beltrami, and beltrami's read by
trimesh: the same positions (to the last bit, or to float32 for STL) and faces."""

import numpy as np
import pytest
import trimesh

import beltrami


def sphere():
    mesh = trimesh.creation.icosphere(subdivisions=2)
    # Long decimal expansions, so that a lossy reader or writer shows.
    return np.asarray(mesh.vertices) * np.pi, np.asarray(mesh.faces)


def triangles_by_position(V, F):
    """The set of triangles as tuples of corner positions, cyclically normalised."""
    out = set()
    for f in F:
        corners = [tuple(V[i]) for i in f]
        k = corners.index(min(corners))
        out.add(tuple(corners[k:] + corners[:k]))
    return out


@pytest.mark.parametrize(
    "name,kwargs",
    [
        ("s.ply", {"encoding": "binary"}),
        ("s.ply", {"encoding": "ascii"}),
        ("s.off", {}),
    ],
)
def test_trimesh_ply_and_off_read_exactly(tmp_path, name, kwargs):
    V, F = sphere()
    path = tmp_path / name
    trimesh.Trimesh(V, F, process=False).export(path, **kwargs)
    V2, F2 = beltrami.read_mesh(path)
    if kwargs.get("encoding") == "binary":
        # trimesh writes PLY positions as float32: read back exactly.
        np.testing.assert_array_equal(V2, V.astype(np.float32).astype(np.float64))
    else:
        # Text with a fixed number of decimals.
        np.testing.assert_allclose(V2, V, atol=1e-6)
    np.testing.assert_array_equal(F2, F)


@pytest.mark.parametrize("file_type", ["stl", "stl_ascii"])
def test_trimesh_stl_reads_welded(tmp_path, file_type):
    V, F = sphere()
    path = tmp_path / "s.stl"
    trimesh.Trimesh(V, F, process=False).export(path, file_type=file_type)
    V2, F2 = beltrami.read_mesh(path)
    # Welding by exact position restores the vertex count; positions are float32 values.
    assert V2.shape == V.shape
    V32 = V.astype(np.float32).astype(np.float64)
    if file_type == "stl":
        assert triangles_by_position(V2, F2) == triangles_by_position(V32, F)
    else:
        np.testing.assert_allclose(np.sort(V2, axis=0), np.sort(V32, axis=0), atol=1e-6)


def test_ply_texture_coordinates_from_trimesh(tmp_path):
    V, F = sphere()
    uv = np.column_stack([V[:, 0], V[:, 1] * 0.5])
    mesh = trimesh.Trimesh(V, F, process=False, visual=trimesh.visual.TextureVisuals(uv=uv))
    path = tmp_path / "uv.ply"
    mesh.export(path)
    _, _, UV = beltrami.read_mesh(path, uv=True)
    np.testing.assert_allclose(UV, uv, atol=1e-6)


@pytest.mark.parametrize("name", ["w.ply", "w.off", "w.stl"])
def test_beltrami_files_read_in_trimesh(tmp_path, name):
    V, F = sphere()
    path = tmp_path / name
    beltrami.write_mesh(path, V, F)
    mesh = trimesh.load(path, process=False)
    if name.endswith(".stl"):
        # trimesh merges STL corners by position too.
        mesh.merge_vertices()
        V32 = V.astype(np.float32).astype(np.float64)
        got = triangles_by_position(np.asarray(mesh.vertices), np.asarray(mesh.faces))
        assert got == triangles_by_position(V32, F)
    else:
        np.testing.assert_array_equal(np.asarray(mesh.vertices), V)
        np.testing.assert_array_equal(np.asarray(mesh.faces), F)


def test_stl_refuses_texture_coordinates(tmp_path):
    V, F = sphere()
    with pytest.raises(beltrami.BeltramiError, match="STL files cannot hold texture coordinates"):
        beltrami.write_mesh(tmp_path / "uv.stl", V, F, uv=V[:, :2])
    assert not (tmp_path / "uv.stl").exists()


def test_glb_texture_coordinates_reach_trimesh(tmp_path):
    V, F = sphere()
    uv = np.column_stack([V[:, 0], V[:, 1]]) * 0.1 + 0.5
    path = tmp_path / "uv.glb"
    beltrami.write_mesh(path, V, F, uv=uv)
    mesh = trimesh.load(path, force="mesh", process=False)
    # glTF puts the texture origin top-left; trimesh flips v on loading.
    np.testing.assert_allclose(mesh.visual.uv[:, 0], uv[:, 0], atol=1e-6)
    np.testing.assert_allclose(1.0 - mesh.visual.uv[:, 1], uv[:, 1], atol=1e-6)


def test_one_based_faces_get_a_hint():
    V, F = sphere()
    with pytest.raises(beltrami.MeshError, match="F looks 1-based .* give F - 1"):
        beltrami.tutte(V, F + 1)
