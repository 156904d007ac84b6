"""The worked example of docs/python.md: the bundled hemisphere mapped onto the unit
disk three ways, each drawn with its faces colored by |mu|.

    python plot_disk_map.py [OUT.png]
"""

import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import beltrami  # noqa: E402

MESHES = pathlib.Path(__file__).resolve().parents[2] / "meshes"


def main(out: str) -> None:
    V, F = beltrami.read_mesh(MESHES / "disk_hemisphere.obj")
    maps = {
        "Tutte (uniform weights)": beltrami.tutte(V, F),
        "harmonic (cotangent)": beltrami.harmonic(V, F),
        "Beltrami flow, conformal": beltrami.beltrami_flow(V, F, target="disk"),
    }
    fig, axes = plt.subplots(1, 3, figsize=(12, 4.4), constrained_layout=True)
    for ax, (name, uv) in zip(axes, maps.items()):
        mu = np.abs(beltrami.beltrami_coefficient(V, F, uv))
        stats = beltrami.distortion(V, F, uv)
        art = ax.tripcolor(uv[:, 0], uv[:, 1], F, facecolors=mu, vmin=0.0, vmax=0.5,
                           cmap="viridis", edgecolors="none")
        ax.set_title(f"{name}\nmean |mu| {stats['mu_mean']:.4f}, max {stats['mu_max']:.3f}")
        ax.set_aspect("equal")
        ax.set_axis_off()
    fig.colorbar(art, ax=axes, shrink=0.8, label="|mu|")
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "disk_maps.png")
