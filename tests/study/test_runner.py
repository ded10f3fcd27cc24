"""Studies on a local Dask cluster of two worker processes: members equal the same case files
run one by one with `fretwear run` (bit for bit), reruns skip finished members, failures are
recorded, a killed worker's member is run again to the same result, and the wear statistics
are the order statistics of the members' own results."""

from __future__ import annotations

import os
import signal
import threading
import time

import numpy as np
import xarray as xr
from helpers.studies import SWEEP, WEAR, base_case, study_file

from fretwear import cli
from fretwear.study.run import run_study

TIMES = ("wall_time", "seconds")  # wall clock figures: the only variables allowed to differ


def assert_same_results(a_path, b_path):
    """Every variable of two results files equal bit for bit (wall times aside)."""
    a, b = xr.open_dataset(a_path).load(), xr.open_dataset(b_path).load()
    assert set(a.variables) == set(b.variables)
    for name in a.variables:
        if any(t in name for t in TIMES):
            continue
        assert a[name].dtype == b[name].dtype, name
        assert np.array_equal(a[name].values, b[name].values,
                              equal_nan=a[name].dtype.kind == "f"), name


def test_members_equal_fretwear_run_and_rerun_skips(tmp_path, client, capsys):
    base_case(tmp_path)
    path = study_file(tmp_path, "[grid]\ncontact.mu = [0.1, 0.3]\n")
    out = tmp_path / "out"
    res = run_study(path, out, scheduler=client, progress=False, echo=False)
    assert res.success and [r.status for r in res.records] == ["ok", "ok"]
    ds = xr.open_dataset(out / "study.nc").load()
    assert list(ds["contact.mu"].values) == [0.1, 0.3]
    for i in (1,):  # (one member: a run costs seconds on a busy machine)
        folder = out / f"member-{i:04d}"
        # the same member case file run by itself with the command line, in this process
        assert cli.main(["run", str(folder / "case.toml"), "-o", str(tmp_path / f"d{i}"),
                         "--no-progress"]) == 0
        assert_same_results(folder / "results.nc", tmp_path / f"d{i}" / "results.nc")
        one = xr.open_dataset(folder / "results.nc").load()
        # study.nc stacks the member's own variables along `member`, unchanged
        assert np.array_equal(ds["slip_amplitude"].values[i], one["slip_amplitude"].values)
    capsys.readouterr()
    stamps = {p: p.stat().st_mtime_ns for p in out.glob("member-*/results.nc")}
    again = run_study(path, out, scheduler=client, progress=False, echo=False)
    assert all(r.skipped for r in again.records)
    assert {p: p.stat().st_mtime_ns for p in out.glob("member-*/results.nc")} == stamps
    assert "(2 finished before)" in again.message


def test_failed_member_is_recorded_not_dropped(tmp_path, client):
    """A boundary name is checked when the model is built, on the worker: the member fails
    with the message of `fretwear run`, and the study says so."""
    base_case(tmp_path)
    path = study_file(tmp_path, '[grid]\ncontact.boundary = ["bottom", "nowhere"]\n')
    out = tmp_path / "out"
    res = run_study(path, out, scheduler=client, progress=False, echo=False)
    assert not res.success
    assert "1 ok, 0 not converged, 1 failed" in res.message and "nowhere" in res.message
    ds = xr.open_dataset(out / "study.nc").load()
    assert list(ds["member_status"].values) == ["ok", "failed"]
    assert "nowhere" in str(ds["member_message"].values[1])
    assert np.all(np.isnan(ds["slip_amplitude"].values[1]))  # never a result
    assert not (out / "member-0001" / "results.nc").exists()
    # a rerun runs the failed member again, skips the other
    res = run_study(path, out, scheduler=client, progress=False, echo=False)
    assert [r.skipped for r in res.records] == [True, False]


def test_wear_ensemble_statistics_are_the_members_order_statistics(tmp_path, client):
    base_case(tmp_path, WEAR)
    path = study_file(tmp_path, "[ensemble]\nmembers = 3\nseed = 5\n[ensemble.perturb]\n"
                      "contact.wear_coefficient = {relative = 0.2}\n")
    out = tmp_path / "out"
    res = run_study(path, out, scheduler=client, progress=False, echo=True)
    assert res.success, res.message
    ds = res.dataset
    finals = []
    for i in range(3):
        one = xr.open_dataset(out / f"member-{i:04d}" / "results.nc").load()
        finals.append(float(one["worn_volume"].values[-1]))
        # the common grid starts at 0 and ends at the last cycle: exact values of the member
        assert ds["worn_volume_on_cycles"].values[i, 0] == one["worn_volume"].values[0]
        assert ds["worn_volume_on_cycles"].values[i, -1] == finals[-1]
        np.testing.assert_array_equal(ds["wear_depth_on_cycles"].values[i, -1],
                                      one["wear_depth"].values[-1])
    assert len(set(finals)) == 3  # the perturbation changed every member
    # median of 3 = the middle member; mean = the arithmetic mean (definitions)
    assert ds["worn_volume_quantile"].sel(quantile=0.5).values[-1] == sorted(finals)[1]
    np.testing.assert_allclose(ds["worn_volume_mean"].values[-1], np.mean(finals), rtol=1e-15)
    q = ds["worn_volume_quantile"].values
    assert np.all(q[0] <= q[1]) and np.all(q[1] <= q[2])
    assert ds["members_reached"].values[-1] == 3
    assert {p.name for p in res.figures} == {"study-worn-volume.png", "study-wear-profiles.png"}


def test_killed_worker_member_continues_from_its_checkpoint_to_the_same_result(tmp_path,
                                                                            client):
    """SIGKILL the worker process running a wear member once the member has saved a
    checkpoint: the scheduler gives the member to a worker again (the nanny restarts the
    killed one), the member continues from its checkpoint (`fretwear run --resume`), and the
    study completes with results equal bit for bit to the same member run undisturbed."""
    base_case(tmp_path, WEAR.replace("max_cycles = 3e5", "max_cycles = 3e6"))
    path = study_file(tmp_path, "[grid]\ncontact.wear_coefficient = [1e-11, 2e-11, 3e-11]\n")
    out = tmp_path / "out"
    box = {}
    thread = threading.Thread(target=lambda: box.setdefault(
        "res", run_study(path, out, scheduler=client, progress=False, echo=False)))
    thread.start()
    killed = None
    deadline = time.time() + 120
    while killed is None and time.time() < deadline and thread.is_alive():
        for worker, keys in client.processing().items():
            names = [str(k).split("-member-")[1][:4] for k in keys]
            saved = [n for n in names if (out / f"member-{n}" / "wear-checkpoint.npz").exists()]
            if saved:
                pid = client.run(os.getpid, workers=[worker])[worker]
                os.kill(pid, signal.SIGKILL)
                killed = saved[0]
                break
        time.sleep(0.02)
    thread.join(240)
    assert killed is not None, "no member was seen running with a checkpoint"
    res = box["res"]
    assert res.success and all(r.status == "ok" for r in res.records), res.message
    assert "resumed from step" in res.records[int(killed)].message
    folder = out / f"member-{killed}"  # the member whose worker was killed, run undisturbed
    assert cli.main(["run", str(folder / "case.toml"), "-o", str(tmp_path / "d"),
                     "--no-progress"]) == 0
    assert_same_results(folder / "results.nc", tmp_path / "d" / "results.nc")


def test_split_sweep_joins_checked_and_equal_to_the_whole_sweep(tmp_path, client):
    """A sweep cut into 2 chunks: the joined curve covers the base sweep's frequencies, the
    join is within join_rtol, and every point equals the unsplit sweep run by `fretwear run`
    to the solver's tolerance (the two started their continuations from different points, so
    they agree as two converged solutions of one balance do, not bit for bit). The chunks'
    linear references, each on its own fine grid, are joined into one increasing grid over
    the band, and agree with the whole sweep's at the sweep's frequencies (both hold them) to
    the projected FRF's accuracy (backward error 1e-8: 1e-6 relative leaves a margin)."""
    assert 'linear_references = []' in SWEEP
    base = base_case(tmp_path, SWEEP.replace('linear_references = []',
                                             'linear_references = ["stuck"]'))
    path = study_file(tmp_path, "[split]\nchunks = 2\n")
    out = tmp_path / "out"
    res = run_study(path, out, scheduler=client, progress=False, echo=False)
    assert res.success, res.message
    ds = res.dataset
    assert cli.main(["run", str(base), "-o", str(tmp_path / "whole"), "--no-progress"]) == 0
    whole = xr.open_dataset(tmp_path / "whole" / "results.nc").load()
    np.testing.assert_allclose(ds["frequency"].values, whole["frequency"].values, rtol=1e-14)
    assert list(ds["join_ok"].values) == [1]
    assert ds["join_frequency"].values[0] == ds["frequency"].values[3]  # 7 points: 0-3, 3-6
    a, b = ds["response_amplitude"].values, whole["response_amplitude"].values
    # 1e-6 of the largest amplitude: the join tolerance, far above the balance's residual
    # tolerance and far below any difference between two different periodic solutions
    assert np.max(np.abs(a - b)) <= 1e-6 * np.max(np.abs(b))
    lf = ds["linear_frequency"].values
    assert np.all(np.diff(lf) > 0) and lf[0] == ds["frequency"].values[0]
    assert lf[-1] == ds["frequency"].values[-1] and lf.size > whole.sizes["linear_frequency"]
    a = ds["linear_response_amplitude"].sel(linear_frequency=ds["frequency"].values).values
    b = whole["linear_response_amplitude"].sel(
        linear_frequency=whole["frequency"].values).values  # the same to 1e-14 (above)
    assert np.max(np.abs(a - b)) <= 1e-6 * np.max(np.abs(b))
