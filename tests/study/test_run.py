"""A study from end to end (fretwear.study.run) without running a member: ``collect`` writes
``study.nc`` from what the members' folders hold, the summary counts what happened, shipped
studies are found by name.

References: a member folder prepared here as a finished run leaves it (its status file with
the hash of its case text, its results file) and the values written into it; the summary's
counts are those of the records, counted by hand. No cluster is started and no member runs
(the runs themselves are tested in test_runner.py).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
import xarray as xr
from helpers.studies import base_case, study_file

from fretwear.errors import InputError
from fretwear.examples import EXAMPLES_DIR
from fretwear.study.members import expand
from fretwear.study.run import _summary, resolve_study, run_study, shipped_studies
from fretwear.study.runner import RESULTS_FILE, STATUS_FILE, MemberRecord, case_hash
from fretwear.study.spec import read_study


def _finished(out, member, amp):
    """Member 0's folder (``member``) in ``out`` as a finished run leaves it: results (``amp`` as
    slip_amplitude) and an "ok" status with the hash of its case text."""
    done = out / member.folder_name
    done.mkdir(parents=True)
    xr.Dataset({"slip_amplitude": (("contact_node", "harmonic"), amp)}).to_netcdf(
        done / RESULTS_FILE, engine="h5netcdf")
    (done / STATUS_FILE).write_text(MemberRecord(0, "ok", "periodic solution",
                                                 case_sha256=case_hash(member.text)).to_json())


def test_collect_writes_the_study_of_the_finished_members_only(tmp_path):
    """Member 0 finished (its status and results as a run leaves them), member 1 never ran:
    ``collect`` records them as "ok" (finished before) and "not run", writes study.nc with
    member 0's values stacked unchanged and NaN for member 1, and the study is not a
    success. study.nc on disk equals the returned dataset."""
    base_case(tmp_path)
    path = study_file(tmp_path, "[grid]\ncontact.mu = [0.1, 0.3]\n")
    members = expand(read_study(path))
    out = tmp_path / "out"
    amp = np.array([[1.0, 2.0], [3.0, 4.0]])
    _finished(out, members[0], amp)
    res = run_study(path, out, collect=True, progress=False, echo=False)
    assert [r.status for r in res.records] == ["ok", "not run"]
    assert not res.success and res.figures == []  # figures = false in the base case
    assert res.message.splitlines()[0] == ("grid study of 2 members: 1 ok, 0 not converged, "
                                           "0 failed, 1 not run (1 finished before)")
    ds = xr.open_dataset(res.results, engine="h5netcdf").load()
    assert res.results == (out / "study.nc").resolve()
    np.testing.assert_array_equal(ds["slip_amplitude"].values[0], amp)
    assert np.all(np.isnan(ds["slip_amplitude"].values[1]))
    assert ds["contact.mu"].values.tolist() == [0.1, 0.3]
    xr.testing.assert_identical(ds, res.dataset)
    assert not (out / members[1].folder_name / RESULTS_FILE).exists()


def test_a_finished_member_of_another_case_text_is_not_taken(tmp_path):
    """A status whose hash is not that of the member's case text (the study was edited
    since) does not count: the member is "not run"."""
    base_case(tmp_path)
    path = study_file(tmp_path, "[grid]\ncontact.mu = [0.1]\n")
    done = tmp_path / "out" / "member-0000"
    done.mkdir(parents=True)
    xr.Dataset({"x": ("a", [1.0])}).to_netcdf(done / RESULTS_FILE, engine="h5netcdf")
    (done / STATUS_FILE).write_text(MemberRecord(0, "ok", case_sha256="0" * 64).to_json())
    res = run_study(path, tmp_path / "out", collect=True, progress=False, echo=False)
    assert [r.status for r in res.records] == ["not run"]


def test_summary_of_a_split_sweep_names_each_failed_join():
    """Counts by status and the joins beyond join_rtol, with their frequencies and
    differences, make the study fail even when every member is ok."""
    study = SimpleNamespace(kind="split", split={"join_rtol": 1e-6})
    records = [MemberRecord(0, "ok"), MemberRecord(1, "ok"), MemberRecord(2, "ok")]
    ds = xr.Dataset({"join_frequency": ("join", [3.0, 5.0]),
                     "join_difference": ("join", [0.0, 1e-3]), "join_ok": ("join", [1, 0])})
    ok, message = _summary(study, records, ds)
    assert not ok
    assert message.splitlines() == ["split study of 3 members: 3 ok, 0 not converged, 0 failed",
                                    "  joins beyond join_rtol = 1e-06: 5 Hz (0.001)"]
    ds["join_ok"].values[1] = 1
    assert _summary(study, records, ds) == (True, "split study of 3 members: 3 ok, 0 not "
                                            "converged, 0 failed\n  every join within "
                                            "join_rtol = 1e-06")


def test_studies_are_found_by_file_or_by_shipped_name(tmp_path):
    """A path is itself; a shipped study's name is its file in the package's studies folder
    (listed here with glob); anything else is one InputError naming what exists."""
    folder = EXAMPLES_DIR / "studies"
    assert shipped_studies() == {p.stem: p for p in sorted(folder.glob("*.toml"))}
    name = "salles2011-frf-mu-load"
    assert resolve_study(name) == folder / f"{name}.toml"
    path = study_file(tmp_path, "")
    assert resolve_study(path) == path
    with pytest.raises(InputError, match=r"no study file 'nope'.*salles2011-frf-mu-load"):
        resolve_study("nope")
    with pytest.raises(InputError, match=r"study file '.*missing.toml' does not exist"):
        resolve_study(tmp_path / "missing.toml")
    with pytest.raises(InputError, match=r"study file 'nowhere.toml' does not exist"):
        resolve_study("nowhere.toml")  # a file name, not a shipped study's name


def _run_members_here(path, out):
    """Run every member of the study ``path`` in this process (run_case into its folder, the
    status file a worker writes), as the Dask tasks do, without starting a cluster."""
    from fretwear.analyses.run import run_case

    members = expand(read_study(path))
    for m in members:
        folder = out / m.folder_name
        folder.mkdir(parents=True)
        (folder / "case.toml").write_text(m.text)
        res = run_case(folder / "case.toml", folder, progress=False, echo=False)
        (folder / STATUS_FILE).write_text(MemberRecord(
            m.index, "ok" if res.success else "not converged", res.summary,
            case_sha256=case_hash(m.text)).to_json())
    return members


def _drawn_study(monkeypatch, path, out):
    """Run the members of the study ``path`` here, then collect it into ``out``, keeping every
    study figure as drawn (``name -> Figure``): ``(result, members, drawn)``."""
    from fretwear.study import figures

    drawn = {}
    save = figures._save
    monkeypatch.setattr(figures, "_save",
                        lambda fig, path: drawn.setdefault(path.name, fig) and save(fig, path))
    members = _run_members_here(path, out)
    return run_study(path, out, collect=True, progress=False, echo=False), members, drawn


def _own(out, member):
    """A member's own results.nc, read back independently of the study's collection."""
    return xr.open_dataset(out / member.folder_name / RESULTS_FILE, engine="h5netcdf").load()


def test_sweep_members_on_different_frequencies_give_a_study_and_its_figure(tmp_path):
    """Two sweep members whose frequencies differ (4 and 6 grid points over the same band: the
    case of a continuation that adds points where each member needs them) and whose kept
    harmonics differ (1 and 1, 2, 3; the two keys tied): study.nc holds their responses on the
    union of their frequencies and harmonics, equal bit for bit to each member's own results.nc
    at its own points and harmonics, NaN for a harmonic it did not keep, linear in frequency in
    between (checked at one midpoint by the formula); member_response_amplitude keeps each
    member's own points; the summary and the attribute common_grid say so, and the FRF family
    figure is written."""
    from helpers.studies import SWEEP

    base_case(tmp_path, SWEEP.replace("n_points = 7", "n_points = 4"))
    path = study_file(tmp_path, "[grid]\n[[grid.tied]]\n\"analysis.n_points\" = [4, 6]\n"
                      "\"analysis.harmonics\" = [1, 3]\n")
    out = tmp_path / "out"
    members = _run_members_here(path, out)
    res = run_study(path, out, collect=True, progress=False, echo=False)
    ds = res.dataset
    assert "response_amplitude" in ds and "common_grid" in ds.attrs
    assert "interpolated" in res.message
    assert [p.name for p in res.figures] == ["study-frf-family.png"]
    own = [xr.open_dataset(out / m.folder_name / RESULTS_FILE, engine="h5netcdf").load()
           for m in members]
    grid = np.unique(np.concatenate([o["frequency"].values for o in own]))
    np.testing.assert_array_equal(ds["frequency"].values, grid)
    np.testing.assert_array_equal(ds["harmonic"].values, [1, 2, 3])
    assert ds["analysis.n_points"].values.tolist() == [4, 6]
    for i, o in enumerate(own):
        on = ds["response_amplitude"].isel(member=i).sel(frequency=o["frequency"].values)
        for h in ds["harmonic"].values:
            if h in o["harmonic"].values:
                np.testing.assert_array_equal(on.sel(harmonic=h).values,
                                              o["response_amplitude"].sel(harmonic=h).values)
            else:
                assert np.all(np.isnan(on.sel(harmonic=h).values))
        m = ds["member_response_amplitude"].isel(member=i).sel(harmonic=1).values
        n = o.sizes["frequency"]
        np.testing.assert_array_equal(m[:n], o["response_amplitude"].sel(harmonic=1).values)
        assert np.all(np.isnan(m[n:]))
    # member 0 (4 points) between its first two points, at a frequency of member 1
    f0, a0 = own[0]["frequency"].values, own[0]["response_amplitude"].sel(harmonic=1).values
    x = grid[(grid > f0[0]) & (grid < f0[1])][0]
    t = (x - f0[0]) / (f0[1] - f0[0])
    np.testing.assert_allclose(ds["response_amplitude"].isel(member=0).sel(
        frequency=x, harmonic=1).values, (1 - t) * a0[0] + t * a0[1], rtol=1e-14)


def test_summary_wraps_between_words_and_prints_worker_warnings_in_one_line():
    """A failed member's long message is printed whole, in lines of at most 100 characters
    broken between words (the words of the lines, joined, are the message's words: none is
    cut); a member's Python warnings are one line each, ``Category: message``, once each,
    without the file name and source line Python prints by default."""
    import warnings

    from fretwear.study.runner import warning_lines

    words = [f"word{i:03d}" for i in range(60)] + ["x" * 120]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for _ in range(2):
            warnings.warn("the preload solve\n  did not converge", RuntimeWarning,
                          stacklevel=1)
    lines = warning_lines(caught)
    assert lines == "RuntimeWarning: the preload solve did not converge"
    records = [MemberRecord(0, "failed", " ".join(words)), MemberRecord(1, "ok",
                                                                        warnings=lines)]
    ok, message = _summary(SimpleNamespace(kind="grid"), records, xr.Dataset())
    body = message.splitlines()[1:]
    assert not ok and all(len(x) <= 100 or x.strip() == "x" * 120 for x in body)
    assert " ".join(body[:-1]).split() == ["member", "0:", "failed:", *words]
    assert body[-1] == ("  member 1: warning: RuntimeWarning: the preload solve did not "
                        "converge")
    assert "test_run.py" not in message


JENKINS = """title = "Jenkins oscillator"
[model]
type = "matrices"
K = "{K}"
M = "{M}"
[contact]
tangential_dofs = [0]
normal_load = 10.0
mu = 0.3
kt = 2e5
[[loads]]
name = "shake"
file = "shake.txt"
waveform = "cos"
[observed]
mass = 0
[analysis]
type = "sweep"
f_min = 50.0
f_max = 90.0
n_points = 5
spacing = "linear"
harmonics = 1
n_samples = 64
linear_references = []
[output]
figures = false
vtu = false
"""


def test_a_study_of_the_excitation_level_gives_the_family_of_frfs_and_its_peaks(tmp_path):
    """The shipped Jenkins oscillator (k = kt = 2e5 N/m, m = 0.5 kg, mu N = 3 N) shaken by
    1 N x excitation_scale over 50-90 Hz, below its stuck resonance (142 Hz): at levels 0.5
    and 1 the element stays stuck (response below mu N / kt = 15 um), so the peak is at
    90 Hz and equals level / (k + kt - m w^2) in closed form to the balance's tolerance
    (1e-8); at level 10 it slips and the peak per unit level is larger (softer). The summary
    gives one line per level and the load-level figure is written."""
    (tmp_path / "shake.txt").write_text("1.0\n")
    (tmp_path / "beam.toml").write_text(JENKINS.format(K=EXAMPLES_DIR / "jenkins-K.mtx",
                                                       M=EXAMPLES_DIR / "jenkins-M.mtx"))
    path = study_file(tmp_path, '[grid]\n"analysis.excitation_scale" = [1.0, 0.5, 10.0]\n')
    out = tmp_path / "out"
    _run_members_here(path, out)
    res = run_study(path, out, collect=True, progress=False, echo=False)
    assert res.success, res.message
    ds = res.dataset
    w = 2 * np.pi * 90.0
    stuck = 1.0 / (2e5 + 2e5 - 0.5 * w**2)
    np.testing.assert_allclose(ds["peak_response_amplitude"].values[:2], [stuck, 0.5 * stuck],
                               rtol=1e-8)
    np.testing.assert_array_equal(ds["peak_frequency"].values, [90.0, 90.0, 90.0])
    assert ds["peak_response_amplitude"].values[2] / 10.0 > 1.05 * stuck
    assert [p.name for p in res.figures] == ["study-frf-family.png", "study-load-levels.png"]
    levels = [x.strip() for x in res.message.splitlines() if x.strip().startswith("level ")]
    assert [x.split(":")[0] for x in levels] == ["level 0.5", "level 1", "level 10"]
    assert levels[1].startswith(f"level 1: peak {stuck:.4g} m at 90 Hz")


def test_a_study_whose_members_have_no_study_figure_says_so(tmp_path):
    """Figures asked (output.figures = true) but the members' results have none that a study
    draws (here only slip_amplitude): the summary says that no study figure was written and
    where each member's figures are, instead of printing nothing about figures."""
    base_case(tmp_path)
    path = study_file(tmp_path, "[set]\noutput.figures = true\n[grid]\ncontact.mu = [0.1]\n")
    members = expand(read_study(path))
    out = tmp_path / "out"
    _finished(out, members[0], np.ones((2, 2)))
    res = run_study(path, out, collect=True, progress=False, echo=False)
    assert res.success and res.figures == []
    assert res.message.splitlines()[-1].startswith("figures: none for the study")


def test_a_nonlinear_modes_study_draws_the_members_backbones(tmp_path, monkeypatch):
    """Two nonlinear-modes members of the shipped Jenkins oscillator (mu = 0.2, 0.3; 4
    amplitudes, 64 samples: a second of CPU): study.nc holds each member's backbone_frequency,
    damping_ratio and modal amplitudes equal bit for bit to its own results.nc (read back
    independently), and study-backbones.png draws exactly those curves, one per member
    labelled with its mu (read back from the figure's lines). Before, such a study stopped
    with a KeyError (its response_amplitude has no frequency axis)."""
    import shutil

    for name in ("jenkins-nonlinear-modes.toml", "jenkins-K.mtx", "jenkins-M.mtx"):
        shutil.copy(EXAMPLES_DIR / name, tmp_path / name)
    case = tmp_path / "jenkins-nonlinear-modes.toml"
    case.write_text(case.read_text().replace("n_amplitudes = 30", "n_amplitudes = 4")
                    .replace("n_samples = 1024", "n_samples = 64")
                    + "\n[output]\nvtu = false\nfigures = false\n")
    path = study_file(tmp_path, "[grid]\ncontact.mu = [0.2, 0.3]\n",
                      base="jenkins-nonlinear-modes.toml")
    out = tmp_path / "out"
    res, members, drawn = _drawn_study(monkeypatch, path, out)
    ds = res.dataset
    assert [p.name for p in res.figures] == ["study-backbones.png"]
    assert ds["member_modal_amplitude"].attrs["units"] == "m kg^0.5"
    fig = drawn["study-backbones.png"]
    for i, m in enumerate(members):
        own = _own(out, m)
        a = own["modal_amplitude"].values
        np.testing.assert_array_equal(ds["member_modal_amplitude"].values[i], a)
        for ax, name in zip(fig.axes, ("backbone_frequency", "damping_ratio"), strict=True):
            np.testing.assert_array_equal(ds[name].values[i], own[name].values)
            line = ax.get_lines()[i]
            assert line.get_label() == f"contact.mu = {(0.2, 0.3)[i]:.3g}"
            np.testing.assert_array_equal(line.get_xdata(), a)
            np.testing.assert_array_equal(line.get_ydata(), own[name].values)
    assert fig.axes[1].get_xlabel() == "modal amplitude [m kg^0.5]"


def test_a_worn_state_study_draws_the_members_worn_profiles(tmp_path, monkeypatch):
    """Two worn-state members of the wear tests' beam block (mu = 0.3, 0.4; 3 harmonics, 32
    samples, residual 1e-2): study.nc holds each member's final worn profile, worn volume,
    maximum depth, stop reason and kind of worn state equal to the last step and attributes
    of its own results.nc (read back independently), and study-worn-profiles.png draws those
    profiles against x, one per member labelled with its mu and its kind."""
    from helpers.cases import WEAR_BLOCK

    (tmp_path / "w.toml").write_text(
        f'title = "worn state"\n{WEAR_BLOCK}[analysis]\ntype = "worn-state"\n'
        "quasi_static = true\nharmonics = 3\nn_samples = 32\ncheckpoint_every_s = 0.0\n"
        "residual_tolerance = 1e-2\n[output]\nvtu = false\nfigures = false\n")
    path = study_file(tmp_path, "[grid]\ncontact.mu = [0.3, 0.4]\n", base="w.toml")
    out = tmp_path / "out"
    res, members, drawn = _drawn_study(monkeypatch, path, out)
    ds = res.dataset
    assert [p.name for p in res.figures] == ["study-worn-profiles.png"]
    lines = drawn["study-worn-profiles.png"].axes[0].get_lines()
    for i, m in enumerate(members):
        own = _own(out, m)
        w = own["wear_depth"].values[-1]
        np.testing.assert_array_equal(ds["final_wear_depth"].values[i], w)
        assert ds["final_max_wear_depth"].values[i] == w.max() > 0
        assert ds["final_worn_volume"].values[i] == own["worn_volume"].values[-1]
        kind = own.attrs["worn_state_kind"]
        assert ds["member_worn_state_kind"].values[i] == kind
        assert ds["member_stop_reason"].values[i] == own.attrs["stop_reason"]
        assert lines[i].get_label() == f"contact.mu = {(0.3, 0.4)[i]:.3g} ({kind})"
        np.testing.assert_array_equal(lines[i].get_xdata(), own["contact_position"].values[:, 0])
        np.testing.assert_array_equal(lines[i].get_ydata(), w)
    assert ds["final_wear_depth"].attrs["units"] == "m"


def test_a_cyclic_modes_study_draws_the_members_frequencies_per_nodal_diameter(tmp_path,
                                                                               monkeypatch):
    """Two cyclic-modes members of the test sector (8 sectors, 2 families; Young's modulus
    1 and 4 x: every frequency doubles, sqrt(4)): study.nc holds each member's
    cyclic_frequency equal bit for bit to its own results.nc (read back independently),
    member 1's twice member 0's (to 1e-9: two eigensolves), and study-cyclic-frequencies.png
    draws those curves against the nodal diameter, one colour per member."""
    from helpers.cyclic import write_sector_case

    base, _ = write_sector_case(tmp_path, 8, 3,
                                analysis='[analysis]\ntype = "cyclic-modes"\nn_modes = 2\n')
    assert "\nE = 2e11\n" in base.read_text()
    path = study_file(tmp_path, "[grid]\nmaterial.E = [2e11, 8e11]\n", base=base.name)
    out = tmp_path / "out"
    res, members, drawn = _drawn_study(monkeypatch, path, out)
    ds = res.dataset
    assert [p.name for p in res.figures] == ["study-cyclic-frequencies.png"]
    lines = drawn["study-cyclic-frequencies.png"].axes[0].get_lines()
    for i, m in enumerate(members):
        own = _own(out, m)
        f = own["cyclic_frequency"].values
        np.testing.assert_array_equal(ds["cyclic_frequency"].values[i], f)
        for j in range(2):
            np.testing.assert_array_equal(lines[2 * i + j].get_xdata(), [0, 1, 2, 3, 4])
            np.testing.assert_array_equal(lines[2 * i + j].get_ydata(), f[:, j])
        assert lines[2 * i].get_color() != lines[2 * (1 - i)].get_color()
    np.testing.assert_allclose(ds["cyclic_frequency"].values[1],
                               2 * ds["cyclic_frequency"].values[0], rtol=1e-9)
    assert ds["cyclic_frequency"].attrs["units"] == "Hz"


def test_a_transient_study_gives_each_members_peak_and_rms_and_draws_them(tmp_path,
                                                                          monkeypatch):
    """Two transient members of the small beam (mu = 0.2, 0.3; 5 periods of 64 steps at
    1.5 kHz): study.nc holds each member's displacement_peak and displacement_rms, computed
    here from its own results.nc's displacement (read back independently: the largest
    |u - mean| and the RMS of u - mean over the period, by hand), and study-response.png draws
    harmonic 1, the peak and the RMS of the first point on its axis of largest response
    against mu."""
    base_case(tmp_path, '[analysis]\ntype = "transient"\nfrequency = 1500.0\nmode = "fixed"\n'
              "n_periods = 5\nsteps_per_period = 64\nmax_periods = 20\n")
    path = study_file(tmp_path, "[grid]\ncontact.mu = [0.2, 0.3]\n")
    out = tmp_path / "out"
    res, members, drawn = _drawn_study(monkeypatch, path, out)
    ds = res.dataset
    assert [p.name for p in res.figures] == ["study-response.png"]
    ax = drawn["study-response.png"].axes[0]
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    axis = int(np.argmax(ds["displacement_harmonic_amplitude"].values[0, 0, :, 0]))
    for i, m in enumerate(members):
        own = _own(out, m)
        u = own["displacement"].values  # (point, axis, tau)
        dyn = u - u.mean(axis=-1, keepdims=True)
        np.testing.assert_allclose(ds["displacement_peak"].values[i], np.abs(dyn).max(-1),
                                   rtol=1e-12)
        np.testing.assert_allclose(ds["displacement_rms"].values[i],
                                   np.sqrt((dyn**2).mean(-1)), rtol=1e-12)
        for label, name in (("harmonic 1", "displacement_harmonic_amplitude"),
                            ("peak over the period (mean apart)", "displacement_peak"),
                            ("RMS over the period (mean apart)", "displacement_rms")):
            want = own[name].values[0, axis, 0] if name.endswith("amplitude") else \
                ds[name].values[i, 0, axis]
            assert lines[label].get_ydata()[i] == want
    np.testing.assert_array_equal(lines["harmonic 1"].get_xdata(), [0.2, 0.3])
    assert ds["displacement_peak"].attrs["units"] == "m"


def test_an_incremental_wear_study_gives_the_wear_statistics_and_figures(tmp_path):
    """Two incremental-wear members of the small beam (mu = 0.2, 0.3; 3 cycles of 16 steps):
    its history has cycles, so study.nc holds the wear members' variables, each member's
    final state equal bit for bit to the last step of its own results.nc (read back
    independently), and the fan chart and the profile band are written."""
    base_case(tmp_path, '[analysis]\ntype = "incremental-wear"\nn_cycles = 3\n'
              "steps_per_cycle = 16\n")
    path = study_file(tmp_path, "[grid]\ncontact.mu = [0.2, 0.3]\n")
    out = tmp_path / "out"
    members = _run_members_here(path, out)
    res = run_study(path, out, collect=True, progress=False, echo=False)
    ds = res.dataset
    assert [p.name for p in res.figures] == ["study-worn-volume.png", "study-wear-profiles.png"]
    for i, m in enumerate(members):
        own = _own(out, m)
        np.testing.assert_array_equal(ds["final_wear_depth"].values[i],
                                      own["wear_depth"].values[-1])
        assert ds["final_worn_volume"].values[i] == own["worn_volume"].values[-1] > 0
        assert ds["final_cycles"].values[i] == own["cycles"].values[-1] == 3
        assert ds["worn_volume_on_cycles"].values[i, -1] == own["worn_volume"].values[-1]
