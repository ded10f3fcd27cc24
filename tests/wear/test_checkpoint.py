"""Wear checkpoints against a hostile world: runs killed by the batch scheduler's SIGTERM or by
SIGKILL, damaged checkpoint files, a folder in the checkpoint's place, and the temporary files
of writes that were killed.

* ``fretwear run CASE`` in a subprocess, killed after its first checkpoint exists, then
  ``--resume``: ``results.nc`` equals the uninterrupted run's bit for bit (wall times aside);
  SIGTERM saves the state it has reached (exit 143, no traceback);
* every kind of damaged checkpoint: exit 2, one line naming the file, the file left as it was;
* a format-3 checkpoint (written by the format-3 writer kept in tests/helpers) resumes to the
  uninterrupted run's history bit for bit; another version is refused in one line;
* stale temporary files of :func:`fretwear.files.atomic_write` are removed at the next run,
  nothing else is.
"""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from helpers.cases import WEAR_BLOCK
from helpers.wear_checkpoints import assert_format_3_is_refused

from fretwear import cli
from fretwear.errors import InputError
from fretwear.examples.builders import stromberg_beam
from fretwear.hb.fourier import FourierBasis
from fretwear.io.results import read_results
from fretwear.wear import HISTORY_FIELDS, RunControl, WearOptions, simulate_wear
from fretwear.wear.checkpoint import CHECKPOINT_VERSION, load_checkpoint, read_history

# A quasi-static wear case of ~400 fixed jumps of 1e4 cycles on an 11-node interface (a few
# seconds). Its first checkpoint is written after step 1, the next one only on an interrupt or
# at the end (checkpoint_every_s = 1e9): a checkpoint at a later step than 1 before the end was
# written by the interrupt.
CASE = f"""
title = "checkpoint robustness: small quasi-static wear"
{WEAR_BLOCK}[analysis]
type = "wear"
quasi_static = true
harmonics = 3
n_samples = 32
adaptive = false
initial_jump = 1e4
max_cycles = 4e6
checkpoint_every_s = 1e9
"""
CKPT = "wear-checkpoint.npz"
N_STEPS = 400
WALL_TIMES = ("step_wall_time",)  # the only variables that differ between identical runs


def fretwear(*args, **kw) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "fretwear", *map(str, args)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)


def finish(proc: subprocess.Popen, timeout: float = 300) -> tuple[int, str, str]:
    out, err = proc.communicate(timeout=timeout)
    return proc.returncode, out, err


@pytest.fixture(scope="module")
def case(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("case") / "wear.toml"
    path.write_text(CASE)
    return path


@pytest.fixture(scope="module")
def reference(case) -> Path:
    """The output folder of the uninterrupted run."""
    out = case.parent / "reference"
    code, _, err = finish(fretwear("run", case, "-o", out, "--no-progress"))
    assert code == 0, err
    return out


def assert_same_results(a: Path, b: Path) -> None:
    """Every variable and attribute equal bit for bit, but wall times and the creation date."""
    x, y = read_results(a), read_results(b)
    assert x.sizes == y.sizes and x.sizes["step"] == N_STEPS + 1
    assert set(x.variables) == set(y.variables)
    for name in x.variables:
        if name not in WALL_TIMES:
            np.testing.assert_array_equal(x[name].values, y[name].values, err_msg=name)
            assert x[name].attrs == y[name].attrs, name
    skip = {"created_utc"}
    # (assert_equal: a NaN attribute, e.g. condensation_f_max of an exact condensation,
    # equals itself)
    np.testing.assert_equal({k: v for k, v in x.attrs.items() if k not in skip},
                            {k: v for k, v in y.attrs.items() if k not in skip})


def wait_for(path: Path, proc: subprocess.Popen, timeout: float = 240.0) -> None:
    t0 = time.monotonic()
    while not path.is_file():
        assert proc.poll() is None, f"the run ended before its first checkpoint: {finish(proc)}"
        assert time.monotonic() - t0 < timeout, "no checkpoint written in time"
        time.sleep(0.02)


# --- killed runs resume to the uninterrupted result ------------------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGKILL], ids=["SIGTERM", "SIGKILL"])
def test_killed_run_resumes_to_the_uninterrupted_results(case, reference, tmp_path, sig):
    out = tmp_path / "out"
    proc = fretwear("run", case, "-o", out, "--no-progress")
    wait_for(out / CKPT, proc)
    time.sleep(0.5)  # some steps after the first checkpoint
    proc.send_signal(sig)
    code, _, err = finish(proc)
    assert "Traceback" not in err
    assert not (out / "results.nc").exists()
    saved = read_history(out / CKPT).n_steps - 1  # the step the checkpoint holds
    assert 1 <= saved < N_STEPS
    if sig == signal.SIGTERM:  # handled as Ctrl-C: the state reached is saved, and said so
        assert code == 143, err
        assert saved > 1  # written by the interrupt, not only the first checkpoint
        assert err.startswith(f"terminated (SIGTERM): saved in {out}: {CKPT}, wear-partial.nc")
        assert err.count("\n") == 1
        partial = read_results(out / "wear-partial.nc")  # the steps of the checkpoint
        assert partial.attrs["complete"] == 0 and partial.attrs["converged"] == 0
        assert partial.sizes["step"] == saved + 1
    else:
        assert code == -signal.SIGKILL and saved == 1

    code, stdout, err = finish(fretwear("run", case, "-o", out, "--resume", "--no-progress"))
    assert code == 0, err
    assert f"(resumed from step {saved})" in stdout
    assert_same_results(out / "results.nc", reference / "results.nc")


def test_sigterm_handler_is_restored_and_fires_once():
    before = signal.getsignal(signal.SIGTERM)
    term = cli.TerminateAsInterrupt()
    with pytest.raises(KeyboardInterrupt), term:
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(5)  # the handler raises at once
    assert term.received and signal.getsignal(signal.SIGTERM) is before
    with cli.TerminateAsInterrupt() as again:
        again.received = True  # a second SIGTERM, while the first one's save goes on
        os.kill(os.getpid(), signal.SIGTERM)  # ignored: no KeyboardInterrupt
    assert signal.getsignal(signal.SIGTERM) is before


# --- damaged checkpoints: one line, exit 2, the file untouched -------------------------------
def _truncated(ok: bytes, path: Path):
    path.write_bytes(ok[: len(ok) // 2])


def _flipped(ok: bytes, path: Path):
    data = bytearray(ok)
    data[len(data) // 2] ^= 0xFF
    path.write_bytes(bytes(data))


def _text(ok: bytes, path: Path):
    path.write_text("step = 3\nthis is not a checkpoint\n")


def _empty(ok: bytes, path: Path):
    path.write_bytes(b"")


def _missing_key(ok: bytes, path: Path):
    tmp = path.with_name("ok.npz")
    tmp.write_bytes(ok)
    with np.load(tmp) as z:
        arrays = {k: z[k] for k in z.files if k != "state_W"}
    tmp.unlink()
    with open(path, "wb") as fh:
        np.savez(fh, **arrays)


def _short_history(ok: bytes, path: Path):
    """Consistent arrays but the history one step short of the state (an incomplete copy)."""
    tmp = path.with_name("ok.npz")
    tmp.write_bytes(ok)
    with np.load(tmp) as z:
        arrays = {k: z[k][:-1] if k.startswith("hist_") else z[k] for k in z.files}
    tmp.unlink()
    with open(path, "wb") as fh:
        np.savez(fh, **arrays)


def _edited_depth(ok: bytes, path: Path):
    """One wear depth made negative and the archive rewritten whole (every CRC right): only
    the checksum of the content can tell."""
    tmp = path.with_name("ok.npz")
    tmp.write_bytes(ok)
    with np.load(tmp) as z:
        arrays = {k: z[k] for k in z.files}
    tmp.unlink()
    arrays["state_W"] = arrays["state_W"].copy()
    arrays["state_W"].flat[0] = -1e-6
    with open(path, "wb") as fh:
        np.savez(fh, **arrays)


def _resealed(value: float):
    """One wear depth set to ``value`` and the checksum recomputed (as someone who read the
    code would): the seal passes, the check of the values must not."""

    def damage(ok: bytes, path: Path):
        from fretwear.files import SEAL, seal

        tmp = path.with_name("ok.npz")
        tmp.write_bytes(ok)
        with np.load(tmp) as z:
            arrays = {k: z[k] for k in z.files if k != SEAL}
        tmp.unlink()
        arrays["state_W"] = arrays["state_W"].copy()
        arrays["state_W"].flat[0] = value
        with open(path, "wb") as fh:
            np.savez(fh, **seal(arrays))

    return damage


DAMAGES = {"truncated": _truncated, "flipped": _flipped, "text": _text, "empty": _empty,
           "missing-key": _missing_key, "short-history": _short_history,
           "edited-depth": _edited_depth, "resealed-nan-depth": _resealed(np.nan),
           "resealed-negative-depth": _resealed(-1e-6)}


@pytest.mark.parametrize("kind", list(DAMAGES))
def test_damaged_checkpoint_is_refused_in_one_line(case, reference, tmp_path, kind, capsys):
    out = tmp_path / "out"
    out.mkdir()
    ck = out / CKPT
    DAMAGES[kind]((reference / CKPT).read_bytes(), ck)
    damaged = ck.read_bytes()
    code = cli.main(["run", str(case), "-o", str(out), "--resume", "--no-progress"])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and err.startswith(f"error: the wear checkpoint '{ck}' is "
                                                   "damaged (")
    assert "delete it to start the run over" in err
    assert ck.read_bytes() == damaged  # left as it was
    assert sorted(p.name for p in out.iterdir()) == [CKPT]  # no results, nothing else
    # the same error for whoever reads it
    with pytest.raises(InputError, match="is damaged"):
        read_history(ck)


def test_damaged_checkpoint_through_the_command_line(case, reference, tmp_path):
    """As users see it: a subprocess, one line on stderr, no traceback."""
    out = tmp_path / "out"
    out.mkdir()
    _flipped((reference / CKPT).read_bytes(), out / CKPT)
    code, _, err = finish(fretwear("run", case, "-o", out, "--resume", "--no-progress"))
    assert code == 2 and "Traceback" not in err
    assert err.startswith(f"error: the wear checkpoint '{out / CKPT}' is damaged (")
    assert err.count("\n") == 1


@pytest.mark.parametrize("resume", [True, False], ids=["resume", "new-run"])
def test_checkpoint_folder_is_refused_before_computing(case, tmp_path, resume, monkeypatch,
                                                       capsys):
    import fretwear.analyses.run as run

    def no_model(*args, **kwargs):
        raise AssertionError("the model was built")

    monkeypatch.setattr(run, "build_model", no_model)
    out = tmp_path / "out"
    (out / CKPT).mkdir(parents=True)
    argv = ["run", str(case), "-o", str(out), "--no-progress"] + (["--resume"] if resume else [])
    assert cli.main(argv) == 2
    err = capsys.readouterr().err
    assert err == (f"error: '{out / CKPT}' is a folder, not a file: move or delete it (the run "
                   "writes its state there)\n")
    assert (out / CKPT).is_dir() and not any((out / CKPT).iterdir())


def test_output_folder_that_is_a_file_is_refused(case, tmp_path, capsys):
    out = tmp_path / "out"
    out.write_text("not a folder")
    assert cli.main(["run", str(case), "-o", str(out), "--no-progress"]) == 2
    assert capsys.readouterr().err.startswith(f"error: the output folder '{out}' is a file")
    assert out.read_text() == "not a folder"


def test_partial_results_are_the_steps_of_the_checkpoint(case, reference, tmp_path):
    """What an interrupted run writes beside its checkpoint: the checkpoint's history as a
    results file marked complete = 0 (here from the finished run's checkpoint: every step),
    its depths those of the history read back from the checkpoint, bit for bit."""
    import shutil

    from fretwear.analyses.run import load_case
    from fretwear.analyses.wear import write_partial
    from fretwear.io.case import build_model

    shutil.copy(reference / CKPT, tmp_path / CKPT)
    c = load_case(case)
    a = c.analysis
    path = write_partial(build_model(c), FourierBasis.up_to(a["harmonics"], a["n_samples"]),
                         a, c, tmp_path)
    ds = read_results(path)
    h = read_history(tmp_path / CKPT)
    assert ds.attrs["complete"] == 0 and ds.attrs["converged"] == 0
    assert ds.attrs["message"].startswith(f"interrupted after {h.n_steps - 1} slow steps")
    np.testing.assert_array_equal(ds["wear_depth"].values[-1], h.wear_depth[-1])
    assert write_partial(None, None, a, c, tmp_path / "nowhere") is None  # no checkpoint


def test_checkpoint_of_another_model_shape(reference):
    """Shapes are checked against the model's (contact nodes, components, coefficients), as
    well as the fingerprint."""
    ck = reference / CKPT
    with np.load(ck) as z:
        key = str(z["fingerprint"])
        nc, d, H = z["hist_U"].shape[1:]
    state, records = load_checkpoint(ck, key, shape=(nc, d, H))
    assert state.step == N_STEPS and len(records) == N_STEPS + 1
    with pytest.raises(InputError, match="different model .*11 contact nodes"):
        load_checkpoint(ck, key, shape=(nc + 1, d, H))
    with pytest.raises(InputError, match="different model"):
        load_checkpoint(ck, "0" * 64, shape=(nc, d, H))


# --- earlier formats ---------------------------------------------------------------------------
def test_interrupted_run_resumes_and_format_3_is_refused(tmp_path):
    """A run interrupted after 3 steps resumes from its checkpoint to the history of the
    uninterrupted run, bit for bit (wall times aside; the same deterministic steps from the
    same state); the same state written in format 3 (the state's earlier names, version 3, no
    content checksum) is refused with a message saying why. Quasi-static Stromberg beam
    (12 x 2), partial slip."""
    model, basis = stromberg_beam(nx=12, ny=2), FourierBasis.up_to(3, 32)
    opts = WearOptions(max_steps=8, tolerance=0.02, checkpoint_every_s=1e9)
    full = simulate_wear(model, basis, quasi_static=True, options=opts)
    ck = tmp_path / "wear.npz"

    def stop(step, record):
        if step == 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        simulate_wear(model, basis, quasi_static=True, options=opts,
                      run=RunControl(checkpoint=ck, callback=stop))
    saved = ck.read_bytes()
    assert_format_3_is_refused(ck)
    ck.write_bytes(saved)
    assert read_history(ck).n_steps == 4
    resumed = simulate_wear(model, basis, quasi_static=True, options=opts,
                            run=RunControl(checkpoint=ck, resume=True))
    assert resumed.resumed_from == 3 and resumed.stop_reason == full.stop_reason == "max_steps"
    for name in HISTORY_FIELDS:
        if name != "wall_time":
            np.testing.assert_array_equal(getattr(resumed.history, name),
                                          getattr(full.history, name), err_msg=name)
    with np.load(ck) as z:
        assert int(z["version"]) == CHECKPOINT_VERSION == 5


@pytest.mark.parametrize("version", [2, 6])
def test_checkpoint_of_another_version_is_refused_in_one_line(reference, tmp_path, version):
    with np.load(reference / CKPT) as z:
        arrays = {k: z[k] for k in z.files}
    arrays["version"] = np.asarray(version)
    ck = tmp_path / CKPT
    np.savez(ck, **arrays)
    with pytest.raises(InputError, match="has another format version") as err:
        load_checkpoint(ck, str(arrays["fingerprint"]))
    assert "\n" not in str(err.value) and str(ck) in str(err.value)


# --- temporary files of killed writes ---------------------------------------------------------
def test_next_run_removes_a_stale_temporary(case, reference, tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    for name in ("results.nc", CKPT):
        (out / name).write_bytes((reference / name).read_bytes())
    stale, other = out / ".results.nc.abc123.tmp", out / "notes.txt"
    stale.write_bytes(b"half a netcdf file")
    other.write_text("mine")
    old = time.time() - 120
    os.utime(stale, (old, old))
    os.utime(other, (old, old))
    kept = {p.name: (p.read_bytes(), p.stat().st_mtime_ns) for p in out.iterdir() if p != stale}
    # (the case text is the reference's: --resume finds the results up to date)
    (out / "case.toml").write_text(CASE)
    code = cli.main(["run", str(out / "case.toml"), "-o", str(out), "--resume",
                     "--no-progress"])
    assert code == 0
    assert "removed .results.nc.abc123.tmp" in capsys.readouterr().out
    assert not stale.exists()
    for name, (data, mtime) in kept.items():
        assert (out / name).read_bytes() == data and (out / name).stat().st_mtime_ns == mtime
