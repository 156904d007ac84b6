"""`beltrami batch`: a broken job among good ones, and resuming after the batch was
killed."""

import json
import os
import signal
import subprocess
import time

from conftest import MESHES


def jobs_file(path, jobs):
    path.write_text("".join(json.dumps(j) + "\n" for j in jobs))
    return path


def report_lines(path):
    return [json.loads(l) for l in path.read_text().splitlines() if l.strip()]


def test_one_broken_job_does_not_stop_the_others(cli, tmp_path):
    mesh = MESHES / "disk_hemisphere.obj"
    jobs = jobs_file(tmp_path / "jobs.jsonl", [
        {"command": "param", "input": str(mesh), "output": str(tmp_path / "a.obj"), "options": {"solver": "lscm"}},
        {"command": "param", "input": str(tmp_path / "missing.obj"), "output": str(tmp_path / "b.obj"), "options": {"solver": "lscm"}},
        {"command": "qc", "input": str(mesh), "output": str(tmp_path / "c.obj"), "options": {"target": "disk", "conformal": True}},
    ])
    report = tmp_path / "report.jsonl"
    run = cli("batch", jobs, "--jobs", "2", "--report", report, check=False)
    assert run.returncode != 0
    lines = report_lines(report)
    assert [l["status"] for l in lines] == ["ok", "error", "ok"]
    assert "missing.obj" in lines[1]["message"]
    assert (tmp_path / "a.obj").exists() and (tmp_path / "c.obj").exists()
    assert not (tmp_path / "b.obj").exists()


def test_resume_after_a_kill_skips_the_finished_jobs(cli, tmp_path):
    mesh = MESHES / "disk_hemisphere.obj"
    outputs = [tmp_path / f"out{k}.obj" for k in range(6)]
    jobs = jobs_file(tmp_path / "jobs.jsonl", [
        {"command": "qc", "input": str(mesh), "output": str(o),
         "options": {"target": "disk", "conformal": True, "p": 4, "max-iters": 40}}
        for o in outputs
    ])
    proc = subprocess.Popen([str(cli.binary), "-q", "batch", str(jobs), "--jobs", "1"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    deadline = time.time() + 120
    while not outputs[0].exists() and time.time() < deadline:
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    finished = [o for o in outputs if o.exists()]
    assert 1 <= len(finished) < len(outputs), "the kill should land mid-batch"
    # Outputs are written atomically: the kill leaves no partial file behind.
    assert not list(tmp_path.glob("*.tmp"))

    report = tmp_path / "report.jsonl"
    cli("batch", jobs, "--resume", "--report", report)
    status = [l["status"] for l in report_lines(report)]
    assert status == ["skipped" if o in finished else "ok" for o in outputs]
    assert all(o.exists() for o in outputs)
