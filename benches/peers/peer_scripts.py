"""What the peer comparison scripts share.

`bootstrap(script, requirements, probe)` re-runs the calling script with the Python of
a virtual environment under ~/.cache/beltrami/peers-venv (or $BELTRAMI_PEERS_VENV),
creating it and installing `requirements` when the import statement `probe` fails
there; `read_obj` reads an OBJ's positions and polygons.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

VENV = Path(
    os.environ.get(
        "BELTRAMI_PEERS_VENV", Path.home() / ".cache" / "beltrami" / "peers-venv"
    )
)


def bootstrap(script: str, requirements: list[str], probe: str) -> None:
    """Returns when already running in the venv; otherwise prepares it and re-runs
    `script` there with the same arguments (does not return)."""
    python = VENV / "bin" / "python"
    if Path(sys.prefix).resolve() == VENV.resolve():
        return
    if not python.exists():
        print(f"creating {VENV}", file=sys.stderr)
        VENV.parent.mkdir(parents=True, exist_ok=True)
        subprocess.run([sys.executable, "-m", "venv", str(VENV)], check=True)
    if subprocess.run([str(python), "-c", probe], capture_output=True).returncode != 0:
        print(f"installing {' '.join(requirements)} into {VENV}", file=sys.stderr)
        subprocess.run(
            [str(python), "-m", "pip", "install", "-q", *requirements], check=True
        )
    os.execv(str(python), [str(python), str(Path(script).resolve()), *sys.argv[1:]])


def read_obj(path: Path):
    """Positions (an (n, 3) array) and polygons (lists of 0-based indices) of an OBJ, in
    the file's order."""
    import numpy as np

    positions, faces = [], []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                positions.append([float(t) for t in line.split()[1:4]])
            elif line.startswith("f "):
                faces.append([int(t.split("/")[0]) - 1 for t in line.split()[1:]])
    return np.array(positions, dtype=np.float64), faces
