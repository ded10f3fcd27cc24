"""Sweep checkpoints: a sweep stopped after any grid frequency resumes to the uninterrupted
sweep's points bit for bit; a damaged or foreign checkpoint is refused in one message naming the
file; a killed ``fretwear run`` of a sweep resumes with ``--resume`` to the same results file.

The reference is the same sweep run without interruption (the resumed run must not differ in a
single bit: its points are re-assembled from the saved harmonics by the same deterministic
code, and the continuation goes on from the same last two points).
"""

import dataclasses
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from helpers.cases import small_case

from fretwear.errors import InputError
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SweepOptions
from fretwear.hb.sweep import sweep
from fretwear.io.results import read_results
from fretwear.model import ContactSpec, Damping, Material, Spring, Traction, from_mesh, rectangle

L, H = 0.02, 0.01  # [m]
BASIS = FourierBasis.up_to(3, 32)
GRID = (2e3, 3e4, 8)  # f_min, f_max [Hz], points: across the block's first resonances


def slipping_block():
    """Steel block 20 x 10 mm (6 x 2 Q4) pressed by 1 MPa on a rigid flat (mu = 0.3), held in x
    by a spring, driven by a cosine pressure of 0.5 MPa on its right face: stick, slip and
    (near resonance) separation along the sweep."""
    return from_mesh(rectangle(L, H, nx=6, ny=2), Material(210e9, 0.3, 7800.0), thickness=0.01,
                     damping=Damping(rayleigh_stiffness=5e-6),
                     supports=[Spring(at=(0.0, H / 2), direction="x", stiffness=1e7)],
                     loads=[Traction("top", pressure=1e6),
                            Traction("right", pressure=5e5, waveform="cos")],
                     contact=ContactSpec("bottom", mu=0.3), observed={"Pe": (L, H / 2)})


class Stop(KeyboardInterrupt):
    pass


def stop_after(n):
    def progress(i, total, pt):
        if i + 1 == n:
            raise Stop
    return progress


def assert_same_points(a, b):
    assert len(a.points) == len(b.points)
    for p, q in zip(a.points, b.points, strict=True):
        assert (p.frequency_hz, p.how, p.flags, p.on_grid, p.time_domain) == \
            (q.frequency_hz, q.how, q.flags, q.on_grid, q.time_domain)
        sp, sq = dataclasses.asdict(p.stats), dataclasses.asdict(q.stats)
        sp.pop("wall_time"), sq.pop("wall_time")
        assert sp == sq
        assert (p.solution is None) == (q.solution is None)
        if p.solution is not None:
            for name in ("U", "lam", "X", "lam_t", "x_t", "state", "anchor"):
                np.testing.assert_array_equal(getattr(p.solution, name),
                                              getattr(q.solution, name), err_msg=name)
            assert p.solution.eps == q.solution.eps
            for k in p.solution.observed:
                np.testing.assert_array_equal(p.solution.observed[k], q.solution.observed[k])


@pytest.fixture(scope="module")
def model():
    return slipping_block()


@pytest.fixture(scope="module")
def reference(model):
    return sweep(model, BASIS, *GRID)


@pytest.mark.parametrize("n_done", [1, 5])
def test_interrupted_sweep_resumes_bit_for_bit(model, reference, tmp_path, n_done):
    ckpt = tmp_path / "sweep.npz"
    with pytest.raises(Stop):
        sweep(model, BASIS, *GRID, options=SweepOptions(checkpoint=ckpt,
                                                        progress=stop_after(n_done)))
    resumed = sweep(model, BASIS, *GRID, options=SweepOptions(checkpoint=ckpt, resume=True))
    assert resumed.resumed_from == n_done
    states = {int(s) for p in reference.points if p.solution for s in np.unique(p.solution.state)}
    assert states >= {1, 2}  # stick and slip occur: the continuation state is not trivial
    assert_same_points(resumed, reference)
    # resuming a finished sweep recomputes nothing and gives the same points again
    again = sweep(model, BASIS, *GRID, options=SweepOptions(checkpoint=ckpt, resume=True))
    assert again.resumed_from == GRID[2]
    assert_same_points(again, reference)


def test_foreign_and_damaged_checkpoints_are_refused(model, tmp_path):
    ckpt = tmp_path / "sweep.npz"
    with pytest.raises(Stop):
        sweep(model, BASIS, *GRID, options=SweepOptions(checkpoint=ckpt, progress=stop_after(2)))
    with pytest.raises(InputError, match="different model or different sweep settings"):
        sweep(model, BASIS, GRID[0], GRID[1], GRID[2] + 1, options=SweepOptions(checkpoint=ckpt,
                                                                                resume=True))
    data = ckpt.read_bytes()
    ckpt.write_bytes(data[: len(data) // 2])
    with pytest.raises(InputError) as err:
        sweep(model, BASIS, *GRID, options=SweepOptions(checkpoint=ckpt, resume=True))
    msg = str(err.value)
    assert str(ckpt) in msg and "damaged" in msg and "\n" not in msg
    ckpt.unlink()
    ckpt.mkdir()
    with pytest.raises(InputError, match="is a folder"):
        sweep(model, BASIS, *GRID, options=SweepOptions(checkpoint=ckpt))


def _edited(src, dst, edit):
    """Copy the checkpoint ``src`` to ``dst`` with ``edit(arrays)`` applied and the archive
    rewritten whole (so every member's CRC is right again: only the content checksum can
    tell)."""
    with np.load(src) as z:
        arrays = {k: z[k] for k in z.files}
    edit(arrays)
    with open(dst, "wb") as fh:
        np.savez(fh, **arrays)


@pytest.mark.parametrize("edit", [
    lambda a: a["U"].__setitem__(Ellipsis, np.nan),                 # harmonics set to NaN
    lambda a: (a["converged"].__setitem__(Ellipsis, True),          # every point converged
               a["U"].__setitem__(Ellipsis, 0.0)),                  # ... with U = 0
    lambda a: a.__setitem__("records", np.asarray(                  # a frequency changed
        str(a["records"]).replace('"frequency_hz": ', '"frequency_hz": 1', 1))),
    lambda a: a.__setitem__("next_index", np.asarray(-1)),          # a negative next index
    lambda a: a["omega"].__setitem__(0, a["omega"][0] * (1 + 1e-15)),  # one value, one ulp
], ids=["U-nan", "all-converged", "frequency", "next-index", "one-ulp"])
def test_edited_checkpoint_with_a_matching_fingerprint_is_refused(model, tmp_path, edit):
    """A checkpoint edited by hand so that its fingerprint still matches (the variants a
    hostile survey resumed silently into a different results file) is refused in one line
    naming the file: the checksum of its content, computed here independently of the
    archive's CRCs, no longer matches. The unedited copy still resumes (the check does not
    refuse good files)."""
    ckpt = tmp_path / "sweep.npz"
    with pytest.raises(Stop):
        sweep(model, BASIS, *GRID, options=SweepOptions(checkpoint=ckpt, progress=stop_after(3)))
    bad = tmp_path / "edited.npz"
    _edited(ckpt, bad, edit)
    with pytest.raises(InputError) as err:
        sweep(model, BASIS, *GRID, options=SweepOptions(checkpoint=bad, resume=True))
    msg = str(err.value)
    assert str(bad) in msg and "damaged" in msg and "\n" not in msg
    assert "does not match its checksum" in msg
    good = sweep(model, BASIS, *GRID, options=SweepOptions(checkpoint=ckpt, resume=True))
    assert good.resumed_from == 3


SWEEP = """[analysis]
type = "sweep"
f_min = 1e3
f_max = 2e4
n_points = 12
harmonics = 3
n_samples = 32
"""


def test_killed_sweep_run_resumes_to_the_same_results_file(tmp_path):
    """``fretwear run`` of a sweep, SIGKILLed once its checkpoint holds some points, then
    ``--resume``: results.nc equals the uninterrupted run's (but wall times and dates). The kill
    lands after the first grid frequency at the earliest (when the checkpoint appears)."""
    case = small_case(tmp_path, SWEEP)

    def run(out, *extra):
        return subprocess.Popen([sys.executable, "-m", "fretwear", "run", str(case), "-o",
                                 str(out), "--no-progress", *extra], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)

    ref = run(tmp_path / "ref")
    killed = run(tmp_path / "out")
    ckpt = tmp_path / "out" / "sweep-checkpoint.npz"
    t0 = time.monotonic()
    while not ckpt.is_file():
        assert killed.poll() is None, killed.communicate()
        assert time.monotonic() - t0 < 240
        time.sleep(0.02)
    killed.send_signal(signal.SIGKILL)
    killed.communicate(timeout=60)
    assert not (tmp_path / "out" / "results.nc").exists()
    code_ref = ref.wait(timeout=300)
    resumed = run(tmp_path / "out", "--resume")
    out, err = resumed.communicate(timeout=300)
    assert resumed.returncode == code_ref, err
    assert "resumed after" in out
    x = read_results(tmp_path / "ref" / "results.nc")
    y = read_results(tmp_path / "out" / "results.nc")
    assert set(x.variables) == set(y.variables)
    for name in x.variables:
        if name == "wall_time":  # of each point's solve: the only variable that differs
            continue
        np.testing.assert_array_equal(x[name].values, y[name].values, err_msg=name)
    skip = {"created_utc", "total_wall_time"}
    # (assert_equal: a NaN attribute, e.g. condensation_f_max of an exact condensation,
    # equals itself)
    np.testing.assert_equal({k: v for k, v in x.attrs.items() if k not in skip},
                            {k: v for k, v in y.attrs.items() if k not in skip})


def _interrupt_after(monkeypatch, n):
    """Ctrl-C right after the ``n``-th checkpoint of a sweep is written (a deterministic
    stand-in for the user's key press)."""
    import fretwear.hb.sweep as hb_sweep

    save, calls = hb_sweep.save_sweep_checkpoint, []

    def save_then_stop(*args, **kwargs):
        save(*args, **kwargs)
        calls.append(1)
        if len(calls) == n:
            raise KeyboardInterrupt
    monkeypatch.setattr(hb_sweep, "save_sweep_checkpoint", save_then_stop)


def test_interrupted_sweep_writes_partial_results(model, tmp_path, monkeypatch):
    """A sweep run through fw.run stopped by Ctrl-C after 3 of 8 grid frequencies writes
    sweep-partial.nc beside its checkpoint, marked complete = 0 and converged = 0: the points
    computed so far, whose responses are the uninterrupted run's at the same frequencies bit
    for bit (the independent reference: the same run not interrupted); --resume then writes
    results.nc and the partial file stays as it was."""
    import fretwear as fw

    keys = dict(f_min=GRID[0], f_max=GRID[1], n_points=GRID[2], harmonics=3, n_samples=32,
                figures=False, vtu=False)
    ref = fw.run(model, "sweep", tmp_path / "ref", **keys).dataset
    _interrupt_after(monkeypatch, 3)
    with pytest.raises(KeyboardInterrupt):
        fw.run(model, "sweep", tmp_path / "out", **keys)
    assert not (tmp_path / "out" / "results.nc").exists()
    part = read_results(tmp_path / "out" / "sweep-partial.nc")
    assert part.attrs["complete"] == 0 and part.attrs["converged"] == 0
    assert part.attrs["message"].startswith("interrupted after 3 of 8 grid frequencies")
    f = part["frequency"].values
    grid = ref["frequency"].values
    assert f.size >= 3  # 3 grid frequencies and any continuation points between them
    at = np.isin(grid, f)
    assert at.sum() == f.size and grid[at].max() < grid.max()
    np.testing.assert_array_equal(part["response_amplitude"].values,
                                  ref["response_amplitude"].values[at])
    np.testing.assert_array_equal(part["converged"].values, ref["converged"].values[at])
    monkeypatch.undo()
    again = fw.run(model, "sweep", tmp_path / "out", resume=True, **keys).dataset
    np.testing.assert_array_equal(again["response_amplitude"].values,
                                  ref["response_amplitude"].values)
    assert (tmp_path / "out" / "sweep-partial.nc").exists()


def test_cli_names_the_partial_results_of_a_sweep(tmp_path, monkeypatch, capsys):
    """``fretwear run`` of a sweep stopped by Ctrl-C says it saved sweep-partial.nc beside the
    checkpoint (exit 130), as a wear run says wear-partial.nc."""
    from fretwear import cli

    case = small_case(tmp_path, SWEEP)
    _interrupt_after(monkeypatch, 1)
    assert cli.main(["run", str(case), "-o", str(tmp_path / "out"), "--no-progress"]) == 130
    err = capsys.readouterr().err
    assert "sweep-checkpoint.npz" in err and "sweep-partial.nc" in err, err
    assert read_results(tmp_path / "out" / "sweep-partial.nc").sizes["frequency"] >= 1
