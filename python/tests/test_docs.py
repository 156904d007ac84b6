"""Every Python code block of docs/python.md, docs/scale.md and docs/atlas.md runs as written, from the
repository's root (where the bundled meshes are): a block of ``>>>`` lines as a doctest
(outputs and error messages compared), any other block saved as a script and run with
``python``, as a user who copies it would."""

import doctest
import os
import re
import subprocess
import sys

import pytest

from conftest import ROOT

DOCS = ["docs/python.md", "docs/scale.md", "docs/atlas.md"]


def python_blocks():
    for doc in DOCS:
        text = (ROOT / doc).read_text(encoding="utf-8")
        for match in re.finditer(r"```python\n(.*?)```", text, re.S):
            line = text.count("\n", 0, match.start()) + 2
            yield pytest.param(doc, line, match.group(1), id=f"{doc}:{line}")


def test_the_docs_have_python_blocks():
    assert len(list(python_blocks())) >= 3


@pytest.mark.parametrize("doc,line,code", list(python_blocks()))
def test_block_runs_as_written(doc, line, code, tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)
    if code.lstrip().startswith(">>>"):
        test = doctest.DocTestParser().get_doctest(code, {}, f"{doc}:{line}", doc, line)
        out = []
        runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
        runner.run(test, out=out.append)
        assert runner.failures == 0, "".join(out)
        return
    if "dask" in code:
        pytest.importorskip("dask.distributed")
    script = tmp_path / "snippet.py"
    script.write_text(code, encoding="utf-8")
    env = dict(os.environ, MPLBACKEND="Agg")
    run = subprocess.run(
        [sys.executable, str(script)], cwd=ROOT, env=env, capture_output=True, text=True, timeout=600
    )
    assert run.returncode == 0, f"{doc}:{line}\n{run.stderr}"


def test_docstring_examples_run(monkeypatch):
    import beltrami

    monkeypatch.chdir(ROOT)
    result = doctest.testmod(beltrami, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0
    assert result.failed == 0
