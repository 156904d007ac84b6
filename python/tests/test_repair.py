"""``repair`` and ``weld``: a triangle soup welded back into the mesh it came from, the
dropped faces named by input row, and the index maps that line results up."""

import numpy as np
import pytest

import beltrami
from conftest import MESHES


def test_a_soup_welds_back_into_the_mesh():
    V, F = beltrami.read_mesh(MESHES / "spot.obj")
    soup_V = V[F.reshape(-1)]
    soup_F = np.arange(3 * len(F)).reshape(-1, 3)
    V2, F2, index = beltrami.weld(soup_V, soup_F)
    assert V2.shape == V.shape
    # Every soup corner lands on the welded vertex at its position, and the faces are
    # the original ones renumbered.
    np.testing.assert_array_equal(V2[index], soup_V)
    np.testing.assert_array_equal(V2[F2], V[F])


def test_repair_drops_degenerate_and_duplicate_faces_and_says_which():
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0.0]])
    F = np.array([[0, 1, 2], [0, 2, 3], [2, 1, 0], [0, 1, 4]])  # face 2 repeats 0, face 3 has no area
    V2, F2, info = beltrami.repair(V, F)
    assert info["dropped_duplicate_faces"] == [2]
    assert info["dropped_degenerate_faces"] == [3]
    assert info["face_index"].tolist() == [0, 1]
    assert info["vertex_index"].tolist() == [0, 1, 2, 3, -1]
    assert info["unreferenced_vertices"] == [4]
    np.testing.assert_array_equal(V2, V[:4])


def test_weld_names_a_face_whose_corners_weld_together():
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 0, 0], [1, 0, 0], [1, 0, 0.0]])
    with pytest.raises(beltrami.MeshError, match="face 1"):
        beltrami.weld(V, [[0, 1, 2], [3, 4, 5]])
    V2, F2, info = beltrami.repair(V, [[0, 1, 2], [3, 4, 5]])
    assert info["dropped_degenerate_faces"] == [1] and len(F2) == 1
