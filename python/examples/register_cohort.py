"""Register a cohort of surfaces onto one template, on one machine or a Dask cluster.

    python register_cohort.py --subjects 40 --workers 2

The cohort is made here: ``--subjects`` smooth random deformations of the bundled cow
(``meshes/spot.obj``), each registered onto the bundled blob (``meshes/blob.obj``) by
:func:`beltrami.register`. Each task reads its subject, registers it and returns the
summary of the registration (the image itself would be written next to the subject in a
real study). ``--workers 0`` runs the same tasks in this process, one after another, for
comparison. docs/scale.md shows the throughput measured on 2 workers.
"""

import argparse
import pathlib
import tempfile
import time

import numpy as np

import beltrami

MESHES = pathlib.Path(__file__).resolve().parents[2] / "meshes"


def make_cohort(folder: pathlib.Path, subjects: int, seed: int = 1) -> list:
    """Writes ``subjects`` deformed cows: each vertex moved by a smooth random field
    (three random Fourier modes per axis, amplitude 5% of the size)."""
    V, F = beltrami.read_mesh(MESHES / "spot.obj")
    size = np.ptp(V, axis=0).max()
    rng = np.random.default_rng(seed)
    paths = []
    for k in range(subjects):
        W = V.copy()
        for axis in range(3):
            for _ in range(3):
                wave = rng.normal(size=3) * 2.0 * np.pi / size
                W[:, axis] += 0.05 * size / 3 * np.sin(V @ wave + rng.uniform(0, 2 * np.pi))
        path = folder / f"subject{k:04d}.obj"
        beltrami.write_mesh(path, W, F)
        paths.append(path)
    return paths


def register_one(path: str, template: str) -> dict:
    """One task: register the subject at ``path`` onto the template."""
    V, F = beltrami.read_mesh(path)
    TV, TF = beltrami.read_mesh(template)
    start = time.perf_counter()
    _, _, _, report = beltrami.register(V, F, TV, TF, info=True)
    return {
        "subject": pathlib.Path(path).name,
        "flipped": report["flipped"],
        "mu_mean": report["mu_mean"],
        "seconds": time.perf_counter() - start,
    }


def run(paths: list, workers: int) -> tuple:
    """The summaries of every task and the wall-clock seconds of the whole run."""
    template = str(MESHES / "blob.obj")
    if workers == 0:
        start = time.perf_counter()
        results = [register_one(str(p), template) for p in paths]
        return results, time.perf_counter() - start
    from dask.distributed import Client, LocalCluster

    # One thread per worker process: a registration uses its core fully.
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True) as cluster:
        with Client(cluster) as client:
            client.submit(register_one, str(paths[0]), template).result()  # warm up every import
            start = time.perf_counter()
            futures = client.map(register_one, [str(p) for p in paths], template=template, pure=False)
            results = client.gather(futures)
            return results, time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--subjects", type=int, default=40)
    parser.add_argument("--workers", type=int, default=2, help="Dask workers (0: this process)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        paths = make_cohort(pathlib.Path(folder), args.subjects)
        results, seconds = run(paths, args.workers)
    flipped = sum(r["flipped"] for r in results)
    mean = np.mean([r["mu_mean"] for r in results])
    print(
        f"{len(results)} registrations on {args.workers or 'no'} workers in {seconds:.2f} s: "
        f"{len(results) / seconds:.2f} per second ({len(results) / seconds * 3600:.0f} per hour), "
        f"mean |mu| {mean:.4f}, flipped faces {flipped}"
    )


if __name__ == "__main__":
    main()
