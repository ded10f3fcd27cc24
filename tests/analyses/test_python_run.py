"""A model built in Python through the case files' run and results path (fretwear.run), and
results obtained in Python written and drawn as the case-file route does
(fretwear.write_results, fretwear.plot).

References: ``fretwear run`` on the same case file (the results file compared variable by
variable), the drivers' own results (``SweepResult.amplitude``, the periodic solution's
harmonics) read back from the file, and the figure and ParaView file names the case-file
analyses write.
"""

from __future__ import annotations

import tomllib

import numpy as np
import pytest
from helpers.studies import PERIODIC, SWEEP, base_case

import fretwear as fw
from fretwear.analyses.common import basis_of
from fretwear.analyses.run import load_case, run_case
from fretwear.errors import InputError
from fretwear.io.case import build_model


def _same_results(a, b):
    """Every variable equal to rounding (1e-12 relative; wall times apart), the same names
    and attributes but those naming the case file."""
    assert set(a.data_vars) == set(b.data_vars) and set(a.coords) == set(b.coords)
    for k in a.variables:
        if "wall_time" in k:
            continue
        if a[k].dtype.kind == "f":
            np.testing.assert_allclose(b[k].values, a[k].values, rtol=1e-12, atol=0)
        else:
            np.testing.assert_array_equal(b[k].values, a[k].values)
    skip = {"case_file", "case_path", "total_wall_time", "created_utc"}
    for k in set(a.attrs) - skip:
        if "wall_time" not in k:
            assert str(a.attrs[k]) == str(b.attrs[k]), k


def test_a_python_model_run_gives_the_results_file_of_the_cli(tmp_path):
    """The beam sweep as a case file through ``fretwear run`` and as a model built from it in
    Python through ``fw.run`` with the same [analysis] table: the same results.nc (every
    variable to rounding), the case_file attribute holding the tables that ran."""
    path = base_case(tmp_path, SWEEP.replace("n_points = 7", "n_points = 4"))
    cli = run_case(path, tmp_path / "cli", progress=False, echo=False)
    case = load_case(path)
    table = tomllib.loads(path.read_text())["analysis"]
    py = fw.run(build_model(case), table, tmp_path / "py", title=case.title, figures=False)
    assert py.success and py.results == (tmp_path / "py" / "results.nc").resolve()
    a, b = fw.read_results(cli.results), fw.read_results(py.results)
    _same_results(a, b)
    assert "fretwear.run()" in b.attrs["case_file"] and "n_points = 4" in b.attrs["case_file"]


def test_python_run_keys_are_checked_as_in_a_case_file(tmp_path):
    """An unknown key and a bad value are one InputError naming the key of [analysis], before
    anything is written."""
    model = build_model(load_case(base_case(tmp_path, PERIODIC)))
    with pytest.raises(InputError, match=r"'f_mni' in \[analysis\]"):
        fw.run(model, "sweep", tmp_path / "out", f_mni=1.0, f_max=2.0, n_points=3)
    with pytest.raises(InputError, match=r"analysis.n_points"):
        fw.run(model, "sweep", tmp_path / "out", f_min=1.0, f_max=2.0, n_points=1)
    with pytest.raises(InputError, match="analysis type"):
        fw.run(model, 3, tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_python_results_are_written_and_drawn_as_the_case_files_do(tmp_path):
    """fw.sweep, fw.solve_periodic and fw.integrate on the beam, then fw.write_results and
    fw.plot: the results read back hold the drivers' own values (SweepResult.amplitude, the
    integration's last period) and the figure and ParaView files are those the sweep,
    periodic and transient analyses write."""
    case = load_case(base_case(tmp_path, SWEEP.replace("n_points = 7", "n_points = 3")))
    model, basis = build_model(case), basis_of(case.analysis)
    frf = fw.sweep(model, basis, 6e3, 8e3, 3)
    ds = fw.read_results(fw.write_results(frf, tmp_path / "sweep", model, basis, title="t"))
    point = str(ds["point"].values[0])
    np.testing.assert_array_equal(
        ds["response_amplitude"].sel(point=point, harmonic=1).isel(axis=1).values,
        frf.amplitude(point, 1, 1))
    assert ds.attrs["analysis_type"] == "sweep" and ds.attrs["title"] == "t"
    names = {p.name for p in fw.plot(frf, tmp_path / "sweep", model, basis)}
    assert names == {f"sweep-{point}.png", "sweep-interface.png"}
    sol = fw.solve_periodic(model, basis, 7e3)
    ds = fw.read_results(fw.write_results(sol, tmp_path / "periodic", model, basis))
    assert ds.attrs["analysis_type"] == "periodic" and int(ds.attrs["converged"]) == 1
    files = {p.name for p in fw.plot(sol, tmp_path / "periodic", model, basis)}
    assert f"periodic-{point}.png" in files and "periodic.pvd" in files
    run = fw.integrate(model, 7e3, n_periods=3)
    ds = fw.read_results(fw.write_results(run, tmp_path / "transient", model))
    np.testing.assert_array_equal(ds["displacement"].sel(point=point).values,
                                  run.observed[point].T)
    files = {p.name for p in fw.plot(run, tmp_path / "transient", model)}
    assert files == {f"transient-{point}.png", f"poincare-{point}.png", "contact-state.png"}
    with pytest.raises(InputError, match="expected the result of fw.sweep"):
        fw.write_results(object(), tmp_path / "x", model, basis)
