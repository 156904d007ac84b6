"""Fixtures of the pytest suite: the bundled meshes, generated meshes and the
``beltrami`` command-line program the calls are compared with."""

import os
import pathlib
import subprocess

import numpy as np
import pytest

import beltrami

ROOT = pathlib.Path(__file__).resolve().parents[2]
MESHES = ROOT / "meshes"


def _binary():
    """The ``beltrami`` program: ``$BELTRAMI_BIN``, else the release build of the
    workspace (``$CARGO_TARGET_DIR`` or ``target/``)."""
    if os.environ.get("BELTRAMI_BIN"):
        return pathlib.Path(os.environ["BELTRAMI_BIN"])
    for target in (os.environ.get("CARGO_TARGET_DIR"), ROOT / "target"):
        if target:
            path = pathlib.Path(target) / "release" / "beltrami"
            if path.exists():
                return path
    return None


class Cli:
    """Runs the ``beltrami`` program."""

    def __init__(self, binary):
        self.binary = binary

    def __call__(self, *args, check=True):
        run = subprocess.run([str(self.binary), "-q", *map(str, args)], capture_output=True, text=True)
        if check and run.returncode != 0:
            raise AssertionError(f"beltrami {' '.join(map(str, args))}: {run.stderr}")
        return run


@pytest.fixture(scope="session")
def cli():
    binary = _binary()
    if binary is None or not binary.exists():
        pytest.skip(
            "SKIPPED: the beltrami program is not built (cargo build --release, or set BELTRAMI_BIN)"
        )
    return Cli(binary)


@pytest.fixture(scope="session")
def hemisphere():
    """A disk in R^3: the bundled hemisphere (1861 vertices, 3600 triangles)."""
    return MESHES / "disk_hemisphere.obj"


@pytest.fixture(scope="session")
def generated(cli, tmp_path_factory):
    """``generated(shape, level, *flags)``: a mesh of ``beltrami generate``, by path."""
    folder = tmp_path_factory.mktemp("generated")

    def make(shape, level, *flags):
        path = folder / f"{shape}{level}{''.join(flags)}.obj"
        if not path.exists():
            cli("generate", shape, "--level", level, *flags, "-o", path)
        return path

    return make


def close(a, b, tol=1e-9):
    """Equal to ``tol`` in every entry (NaN where the other is NaN)."""
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape, f"shapes {a.shape} and {b.shape}"
    assert np.allclose(a, b, rtol=0.0, atol=tol, equal_nan=True), (
        f"largest difference {np.nanmax(np.abs(a - b)):.3e} > {tol}"
    )
