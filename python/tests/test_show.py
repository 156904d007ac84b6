"""``show`` through polyscope: the calls it makes (a stand-in module records them, so no
window opens), and the error without polyscope."""

import sys
import types

import numpy as np
import pytest

import beltrami
from conftest import MESHES


class Recorder:
    """Stands in for polyscope and for its surface mesh, recording calls."""

    def __init__(self):
        self.calls = []

    def __getattr__(self, name):
        def call(*args, **kwargs):
            self.calls.append((name, args, kwargs))
            return self

        return call


def test_show_hands_the_map_and_mu_to_polyscope(monkeypatch):
    recorder = Recorder()
    module = types.ModuleType("polyscope")
    for name in ("init", "register_surface_mesh", "show"):
        setattr(module, name, getattr(recorder, name))
    monkeypatch.setitem(sys.modules, "polyscope", module)
    V, F = beltrami.read_mesh(MESHES / "disk_hemisphere.obj")
    uv = beltrami.lscm(V, F)
    mu = beltrami.beltrami_coefficient(V, F, uv)
    beltrami.show(V, F, uv=uv, mu=mu, name="hemisphere")
    names = [c[0] for c in recorder.calls]
    assert names == ["init", "register_surface_mesh", "add_parameterization_quantity",
                     "add_scalar_quantity", "show"]
    _, (name, v, f), _ = recorder.calls[1]
    assert name == "hemisphere" and v.shape == V.shape and f.shape == F.shape
    _, (label, values), kwargs = recorder.calls[3]
    np.testing.assert_allclose(values, np.abs(mu))
    assert kwargs["defined_on"] == "faces" and kwargs["vminmax"] == (0.0, 1.0)
    with pytest.raises(beltrami.FieldError, match="one value per face"):
        beltrami.show(V, F, mu=mu[:-1])


def test_show_without_polyscope_says_how_to_get_it(monkeypatch):
    monkeypatch.setitem(sys.modules, "polyscope", None)
    V, F = beltrami.read_mesh(MESHES / "disk_hemisphere.obj")
    with pytest.raises(beltrami.UnsupportedError, match=r'pip install "beltrami\[view\]"'):
        beltrami.show(V, F)
