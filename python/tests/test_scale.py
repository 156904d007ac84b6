"""The Dask example of docs/scale.md on a small cohort (optional: skipped without
dask.distributed)."""

import importlib
import pathlib

import pytest

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"


def test_a_cohort_on_two_dask_workers_gives_the_results_of_one_process(tmp_path, monkeypatch):
    pytest.importorskip("dask.distributed", reason="SKIPPED: dask.distributed is not installed")
    # The worker processes start with this process's sys.path and import the example's
    # task function by its module name.
    monkeypatch.syspath_prepend(str(EXAMPLES))
    register_cohort = importlib.import_module("register_cohort")
    paths = register_cohort.make_cohort(tmp_path, 4)
    serial, _ = register_cohort.run(paths, 0)
    parallel, _ = register_cohort.run(paths, 2)
    assert [r["subject"] for r in parallel] == [r["subject"] for r in serial]
    for a, b in zip(serial, parallel):
        assert a["flipped"] == b["flipped"] == 0
        assert a["mu_mean"] == b["mu_mean"]
