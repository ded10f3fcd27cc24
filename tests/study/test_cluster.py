"""A study through `--scheduler` on a real cluster: a `dask scheduler` and two `dask worker`
processes started here on localhost (stopped in a `finally`, whatever happens), and the
`fretwear study` client killed (SIGKILL) in the middle of the study: the rerun skips the
members finished before and completes the others."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import xarray as xr
from helpers.studies import base_case, study_file, worker_env

START_S = 60  # the scheduler file appears and both workers join within this (loaded machine)
RUN_S = 240  # bound of each `fretwear study` run


def _stop(procs):
    for p in procs:
        if p.poll() is None:
            p.send_signal(signal.SIGTERM)
    for p in procs:
        try:
            p.wait(10)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait(10)


def _cluster(tmp_path: Path, env: dict):
    """Start a scheduler and two one-thread workers; returns (address, processes)."""
    sched_file = tmp_path / "scheduler.json"
    dask = str(Path(sys.executable).with_name("dask"))  # the `dask` command of this Python
    log = open(tmp_path / "cluster.log", "w")  # noqa: SIM115 (closed with the processes)
    procs = [subprocess.Popen([dask, "scheduler",
                               "--scheduler-file", str(sched_file), "--no-dashboard",
                               "--host", "127.0.0.1", "--port", "0"],
                              env=env, stdout=log, stderr=log)]
    deadline = time.time() + START_S
    while not sched_file.is_file() and time.time() < deadline:
        time.sleep(0.2)
    address = json.loads(sched_file.read_text())["address"]
    for _ in range(2):
        procs.append(subprocess.Popen([dask, "worker", address,
                                       "--nthreads", "1", "--no-dashboard",
                                       "--host", "127.0.0.1"],
                                      env=env, stdout=log, stderr=log))
    from distributed import Client

    with Client(address, timeout=START_S) as c:
        c.wait_for_workers(2, timeout=START_S)
    return address, procs


def test_study_on_a_real_scheduler_survives_a_killed_client(tmp_path):
    base_case(tmp_path)
    path = study_file(tmp_path, "[grid]\ncontact.mu = [0.1, 0.2, 0.3, 0.4]\n")
    out = tmp_path / "out"
    env = worker_env()
    procs = []
    try:
        address, procs = _cluster(tmp_path, env)
        cmd = [sys.executable, "-m", "fretwear", "study", str(path), "-o", str(out),
               "--scheduler", address, "--no-progress"]
        client = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        procs.append(client)
        deadline = time.time() + RUN_S
        while time.time() < deadline and client.poll() is None \
                and not list(out.glob("member-*/status.json")):
            time.sleep(0.05)
        killed = client.poll() is None
        if killed:
            os.kill(client.pid, signal.SIGKILL)  # the client dies with members in flight
            client.wait(10)
        before = {p.parent.name for p in out.glob("member-*/status.json")}
        assert before, "no member finished before the client was killed"
        again = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=RUN_S)
        assert again.returncode == 0, again.stderr[-2000:]
        assert "4 ok, 0 not converged, 0 failed" in again.stdout
        if killed and len(before) < 4:
            assert "finished before" in again.stdout
        ds = xr.open_dataset(out / "study.nc").load()
        assert list(ds["contact.mu"].values) == [0.1, 0.2, 0.3, 0.4]
        assert list(ds["member_status"].values) == ["ok"] * 4
        # every member's results are the ones in its own folder, whichever run made them
        for i in range(4):
            one = xr.open_dataset(out / f"member-{i:04d}" / "results.nc").load()
            assert np.array_equal(ds["slip_amplitude"].values[i], one["slip_amplitude"].values)
    finally:
        _stop(procs[::-1])


_CLIENT_DIES = """
import os, sys

def main():
    import psutil
    from fretwear.study.runner import dask_client
    with dask_client(None, 1) as client:
        client.run(os.getpid)
        print(*[p.pid for p in psutil.Process().children(recursive=True)], flush=True)
        raise MemoryError("the client ran out of memory")

if __name__ == "__main__":
    main()
"""


def test_a_client_dying_of_memory_error_leaves_no_process(tmp_path):
    """The client of a LocalCluster (the default of `fretwear study`) dies of a MemoryError
    while its worker runs: every process it started (worker, nanny, resource tracker), listed
    by the operating system while the cluster ran, is gone once the client has exited, which
    is what the issue found left running."""
    import psutil

    script = tmp_path / "client.py"
    script.write_text(_CLIENT_DIES)
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                         env=worker_env(), timeout=RUN_S, cwd=tmp_path)
    assert out.returncode == 1 and "MemoryError" in out.stderr
    children = [int(p) for p in out.stdout.split()]
    assert children  # the worker was listed
    deadline = time.monotonic() + 30
    alive = children
    while alive and time.monotonic() < deadline:
        alive = [p for p in alive if psutil.pid_exists(p)
                 and psutil.Process(p).status() != psutil.STATUS_ZOMBIE]
        time.sleep(0.5)
    assert not alive, f"processes left running: {alive}"
