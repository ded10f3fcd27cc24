"""The DLFT analysis ``periodic`` run from case files through the command line.

A small variant of the paper's beam (10 x 2 elements, 3 harmonics, 32 samples per period) keeps
each run to a few seconds. The results files are checked against the tables of
docs/results.md (every variable written is documented in its analysis' section with the same
units and dimensions); a solve that did not converge must leave no solution in the file.
"""

import re

import meshio
import numpy as np
import pytest
from helpers.cases import LINEAR_EXAMPLE, ROOT, check_documented, run, small_case, with_key

from fretwear import cli
from fretwear.analyses.run import load_case
from fretwear.io.results import read_results

DLFT_EXAMPLES = ("salles2011-79khz-periodic", "salles2011-frf", "beam-quasistatic-periodic")

PERIODIC = """[analysis]
type = "periodic"
frequency = 1e4
harmonics = 3
n_samples = 32
"""


def test_variable_names_mean_one_thing_across_docs():
    """A name documented twice must have the same units and dimensions, except for the
    documented convention that a branch of periodic states records each state's quantity
    under the same name with the branch's leading dimension (``step`` of a wear history,
    ``frequency`` of a sweep, ``modal_amplitude`` of a nonlinear mode; docs/results.md,
    rules): that leading dimension is set aside before comparing (a branch's scalar compares
    as ``branch``)."""
    seen = {}
    for line in (ROOT / "docs" / "results.md").read_text().splitlines():
        m = re.match(r"\| `(\w+)` \| ([^|]*) \| ([^|]*) \|", line)
        if m:
            dims, units = m.group(2).strip(), m.group(3).strip()
            first, _, rest = dims.partition(", ")
            if first in ("step", "frequency", "modal_amplitude"):
                dims = rest or "branch"
            row = (dims, units)
            assert seen.setdefault(m.group(1), row) == row, m.group(1)


# --- periodic -------------------------------------------------------------------------------
def test_periodic_writes_documented_results_figures_and_paraview(tmp_path, capsys):
    status, out, err = run(small_case(tmp_path, PERIODIC), capsys)
    assert status == 0, err
    assert "periodic at 10 kHz: converged" in out
    res = tmp_path / "beam-results"
    ds = read_results(res / "results.nc")
    assert ds.attrs["analysis_type"] == "periodic"
    assert ds.attrs["converged"] == 1
    assert ds.attrs["open_under_preload"] == "" and "warning" not in out
    assert ds.attrs["warnings"] == ""  # the static preload solve converged
    assert "slow_multiplier" in ds.attrs
    assert ds.sizes == {"point": 1, "axis": 2, "contact_node": 11, "component": 2,
                        "harmonic_coefficient": 7, "tau": 32, "harmonic": 3}
    check_documented(ds, "periodic")
    for key in ("residual", "iterations", "nfev", "njev", "wall_time", "eps", "solver"):
        assert key in ds.attrs, key
    assert ds.attrs["residual"] <= 1e-8 and ds.attrs["eps"] > 0
    assert ds.attrs["excitation_frequency"] == 1e4
    state = ds["contact_state"]
    assert state.dtype == np.int8 and set(np.unique(state.values)) <= {0, 1, 2}
    assert state.attrs["flag_meanings"] == "separation stick slip"
    # the friction energy per node adds up to the total; the pressure carries the preload
    np.testing.assert_allclose(ds["dissipated_energy"].sum(), ds["total_dissipated_energy"])
    assert float(ds["pressure_mean"].mean()) == pytest.approx(1e4, rel=0.1)
    for stem in ("periodic-Pe", "contact-state", "contact-profiles", "hysteresis"):
        assert (res / f"{stem}.png").stat().st_size > 10_000, stem
    # ParaView: one .vtu per instant; the full field at P_e is the observed displacement
    pvd = (res / "periodic.pvd").read_text()
    files = re.findall(r'file="([^"]+)"', pvd)
    assert len(files) == 32
    m = meshio.read(res / files[7])
    node = np.argmin(np.linalg.norm(m.points[:, :2] - ds["point_position"].values[0], axis=1))
    np.testing.assert_allclose(m.point_data["displacement"][node, :2],
                               ds["displacement"].values[0, :, 7], rtol=1e-8, atol=1e-20)


def test_quasi_static_needs_no_frequency_and_takes_a_list_of_harmonics(tmp_path, capsys):
    analysis = ('[analysis]\ntype = "periodic"\nquasi_static = true\nharmonics = [1, 3]\n'
                "n_samples = 16\n")
    text = small_case(tmp_path, analysis).read_text() + '[output]\nvtu = false\n'
    path = tmp_path / "qs.toml"
    path.write_text(text)
    status, out, err = run(path, capsys)
    assert status == 0, err
    assert "periodic at quasi-static loading: converged" in out
    ds = read_results(tmp_path / "qs-results" / "results.nc")
    assert ds.attrs["quasi_static"] == 1 and ds.attrs["excitation_frequency"] == 1.0
    assert ds["harmonic"].values.tolist() == [1, 3]
    assert ds["harmonic_coefficient"].values.tolist() == ["0", "c1", "c3", "s1", "s3"]
    assert not (tmp_path / "qs-results" / "periodic.pvd").exists()


def test_an_interface_open_under_the_preload_is_a_warning_and_an_attribute(tmp_path, capsys):
    """The beam held above its flat by stiff vertical springs at its top corners (10 N of
    pressure against 2 x 1e9 N/m: 5e-9 m, less than the 1e-6 m gap): no node touches under
    the preload. The run goes on (a clearance the vibration closes may be meant), says so
    before it starts and records the interface in the results."""
    text = small_case(tmp_path, PERIODIC).read_text()
    text = text.replace("gap = 0.0", "gap = 1e-6").replace(
        "[[loads]]", "".join(f'[[springs]]\nat = "{at}"\ndirection = "y"\nstiffness = 1e9\n\n'
                             for at in ("top_left", "top_right")) + "[[loads]]", 1)
    path = tmp_path / "held.toml"
    path.write_text(text + "[output]\nvtu = false\nfigures = false\n")
    status, out, err = run(path, capsys)
    assert status == 0, err
    assert ("warning: interface 'contact' is open at all its 11 nodes under the static loads "
            "(the preload; its smallest initial gap is 1e-06 m)") in out
    ds = read_results(tmp_path / "held-results" / "results.nc")
    assert ds.attrs["open_under_preload"] == "contact"
    assert (ds["contact_state"].values == 0).all()  # and the vibration does not close it


def test_a_periodic_solve_that_fails_saves_no_solution(tmp_path, capsys):
    # without the time-domain start, which would rescue this solve (the next test)
    path = small_case(tmp_path, with_key(PERIODIC, "max_iter = 1\ntime_domain = false"))
    status, out, err = run(path, capsys)
    assert status == 1
    assert err == ""
    line = next(x for x in out.splitlines() if "did not converge" in x)
    assert line.startswith("periodic solve at 10 kHz did not converge: maximum number of "
                           "iterations reached (relative residual ")
    assert "No solution was saved" in line
    res = tmp_path / "beam-results"
    ds = read_results(res / "results.nc")
    assert ds.attrs["converged"] == 0
    assert len(ds.variables) == 0  # no solution, not even the coordinates
    assert ds.attrs["iterations"] == 1 and ds.attrs["residual"] > 1e-8
    assert not list(res.glob("*.png")) and not (res / "periodic.pvd").exists()


def test_a_failed_solve_reports_its_attempts_and_the_time_integration(tmp_path, capsys):
    """The same starved solve (max_iter = 1) with the default time_domain = true: every
    attempt of the strategy fails, then the time integration settles to a periodic state whose
    solve (2 x max_iter iterations) fails too; the diagnostics of results.nc and the summary
    name every attempt and what the integration found, and no solution is saved."""
    path = small_case(tmp_path, with_key(PERIODIC, "max_iter = 1"))
    status, out, err = run(path, capsys)
    assert status == 1
    ds = read_results(tmp_path / "beam-results" / "results.nc")
    assert ds.attrs["converged"] == 0 and len(ds.variables) == 0
    methods = [a.split("/")[0] for a in ds.attrs["attempts"].split("; ")]
    assert methods == ["start", "best-point", "eps-continuation", "eps-continuation",
                       "harmonic-continuation", "time-start"]
    assert ds.attrs["time_domain"].startswith("time integration: periodic steady state")
    assert "attempts: start, best-point" in out and ds.attrs["time_domain"] in out


# --- input errors ---------------------------------------------------------------------------
@pytest.mark.parametrize("line, message", [
    ("n_samples = 6", "analysis.n_samples = 6: expected more than 6 samples per period "
                      "(twice the highest harmonic, 3)"),
    ("frequency = -50.0", "analysis.frequency = -50.0: expected a number > 0"),
    ('solver = "powel"', 'analysis.solver = "powel": expected one of "powell", "newton", '
                         '"hybr" (did you mean "powell"?)'),
    ('eps = "paper"', 'analysis.eps = "paper": expected one of "auto", "static", "top", "stiff", '
                      '"contact" or a number > 0'),
    ("harmonics = 0", "analysis.harmonics = 0: expected an integer >= 1 or a non-empty list "
                      "of integers >= 1 (no repeats)"),
    ('condensation = "craig"', 'analysis.condensation = "craig": expected one of "auto", '
                               '"exact", "modal"'),
    ("condensation_tol = 0.0", "analysis.condensation_tol = 0.0: expected a number > 0"),
    ("condensation_modes = -1", "analysis.condensation_modes = -1: expected an integer >= 0"),
])
def test_bad_periodic_input_gives_one_clear_line(tmp_path, capsys, line, message):
    status, out, err = run(small_case(tmp_path, with_key(PERIODIC, line)), capsys)
    assert status == 2
    assert err == f"error: {message}\n"
    assert not (tmp_path / "beam-results").exists()


def test_each_condensation_runs_and_is_recorded(tmp_path, capsys):
    """The case file's ``condensation`` choices: ``exact``, ``modal`` (the beam's modes raised
    until the check passes, with residual vectors) and ``auto`` (exact on this 2D beam: its
    interior is small). The modal solve is compared with the exact one: the observed
    displacement agrees within the check's tolerance (1e-3 relative, the bound of the error
    of ``Z_r`` and of the observed point's recovery at the top harmonic; measured 3.4e-5)."""
    out = {}
    for method in ("exact", "modal", "auto"):
        folder = tmp_path / method
        folder.mkdir()
        status, text, err = run(small_case(folder, with_key(PERIODIC,
                                                            f'condensation = "{method}"')),
                                capsys)
        assert status == 0, err
        ds = read_results(folder / "beam-results" / "results.nc")
        assert ds.attrs["condensation_asked"] == method
        assert f"condensation: {ds.attrs['condensation']} (asked {method}" in text
        out[method] = ds
    assert out["exact"].attrs["condensation"] == "exact" == out["auto"].attrs["condensation"]
    assert "interior DOFs <" in out["auto"].attrs["condensation_reason"]
    m = out["modal"].attrs
    assert m["condensation"] == "modal" and 0 < m["condensation_error"] <= m["condensation_tol"]
    assert m["condensation_max_order"] == 3 and m["condensation_f_max"] == 1e4
    ref = out["exact"]["displacement"].values
    diff = np.abs(out["modal"]["displacement"].values - ref).max()
    assert diff <= m["condensation_tol"] * np.abs(ref).max()
    np.testing.assert_array_equal(out["auto"]["displacement"].values, ref)


def test_frequency_is_required_unless_quasi_static(tmp_path, capsys):
    status, _, err = run(small_case(tmp_path, '[analysis]\ntype = "periodic"\n'), capsys)
    assert status == 2
    assert err.startswith("error: missing required key 'analysis.frequency' (excitation "
                          "frequency [Hz]")
    assert len(err.splitlines()) == 1


# --- shipped examples -----------------------------------------------------------------------
@pytest.mark.parametrize("name", DLFT_EXAMPLES)
def test_examples_share_the_model_of_the_linear_example(name):
    """Same model text (and comments) as beam-linear-frf: the figures compare like with like."""
    def model_part(path):
        text = path.read_text()
        return text[text.index("[model]"): text.index("[analysis]")]

    path = cli.examples()[name]
    assert model_part(path) == model_part(LINEAR_EXAMPLE)
    case = load_case(path)
    assert case.analysis["type"] in ("periodic", "sweep")
    assert case.title.startswith("Salles 2011 section 4.2 beam")


@pytest.mark.parametrize("analysis", ["periodic", "sweep"])
def test_a_failed_static_preload_solve_is_a_warning_and_an_attribute(tmp_path, capsys,
                                                                      monkeypatch, analysis):
    """The static contact problem under the preload (whose solution gives the stick anchors)
    is given no iteration (its start, contact closed and stuck, is not its solution): the run
    goes on with anchors at 0 but says so, on the terminal and in the ``warnings`` attribute
    of the results; with the normal iteration limit the attribute is empty (asserted by
    test_periodic_writes_documented_results_figures_and_paraview and the sweep's
    test_sweep_writes_documented_results_and_figures)."""
    from fretwear.hb import preload

    table = PERIODIC if analysis == "periodic" else (
        '[analysis]\ntype = "sweep"\nf_min = 9e3\nf_max = 1e4\nn_points = 2\nharmonics = 1\n'
        "n_samples = 16\n")
    monkeypatch.setattr(preload, "STATIC_MAX_ITER", 0)
    path = tmp_path / "starved.toml"
    path.write_text(small_case(tmp_path, table).read_text()
                    + "[output]\nvtu = false\nfigures = false\n")
    status, out, err = run(path, capsys)
    ds = read_results(tmp_path / "starved-results" / "results.nc")
    expected = "the static contact problem under the preload did not converge ("
    assert ds.attrs["warnings"].startswith(expected), ds.attrs["warnings"]
    assert "stick anchors are set to 0" in ds.attrs["warnings"]
    assert f"warning: {ds.attrs['warnings']}" in out


def test_a_model_without_observed_points_runs(tmp_path, capsys):
    """A periodic run of a model that observes no point writes its results (it failed while
    writing them, on the observed variables' dimensions): the contact results are there and
    equal those of the same case with an observed point (the observed point does not enter
    the balance: bit for bit)."""
    with_point = small_case(tmp_path, PERIODIC, "with.toml")
    text = with_point.read_text()
    start = text.index("[observed]")
    end = text.index("\n[", start + 1)
    without = tmp_path / "without.toml"
    without.write_text(text[:start] + text[end + 1:])
    assert "[observed]" not in without.read_text()
    for path in (with_point, without):
        status, out, err = run(path, capsys)
        assert status == 0, err
    a = read_results(tmp_path / "with-results" / "results.nc")
    b = read_results(tmp_path / "without-results" / "results.nc")
    assert "displacement" in a and "displacement" not in b
    np.testing.assert_array_equal(a["contact_force"].values, b["contact_force"].values)


def test_hill_stability_says_what_the_state_is(tmp_path, capsys):
    """``hill_stability = true``: the summary says whether the state is stable, and the
    attributes record it. References independent of Hill's method: the neutral directions are
    the nodes whose ``contact_state`` is stick over the whole period (one tangential direction
    each in 2D: a family of stuck states), and the verdict is that of the largest multiplier
    recorded (above 1: unstable). One harmonic keeps Hill's dense problem small."""
    analysis = with_key(with_key(PERIODIC, "harmonics = 1"), "hill_stability = true")
    path = small_case(tmp_path, analysis + "[output]\nvtu = false\nfigures = false\n")
    status, out, err = run(path, capsys)
    assert status == 0, err
    ds = read_results(tmp_path / "beam-results" / "results.nc")
    stuck = int(np.all(ds["contact_state"].values == 1, axis=-1).sum())
    assert stuck > 0 and ds.attrs["neutral_directions"] == stuck
    text = ds.attrs["floquet_multipliers"]  # empty: no exponent above NEGLIGIBLE
    top = float(text.split(",")[0].split()[0]) if text else 0.0
    assert ds.attrs["hill_stable"] in ((1,) if top <= 1 + 1e-6 else (0, -1))
    assert ds.attrs["stability_notes"] == ""
    word = ("stable by Hill's method" if top <= 1 else "UNSTABLE by Hill's method"
            if ds.attrs["hill_stable"] == 0 else "stability UNDECIDED by Hill's method")
    assert word in out and f"{stuck} tangential direction(s)" in out


def test_a_state_held_only_weakly_is_said_so():
    """The summary line and the attribute ``slow_multiplier`` of :func:`slow_verdict` on a
    slider held by a weak spring (tests/helpers/slow.py; the multiplier itself is checked
    against the time integration in tests/hb/test_slow_mode.py): with ``kw`` 1e-4 a start
    elsewhere relaxes over 346 periods, below the 1000 of a slow state: no line; with ``kw``
    1e-5 over about 3500: the line says the state is where a drift ends. With ``kw`` 0.1 the
    balance is not nearly singular: NaN, no line. The small beam of the other tests records
    the attribute (test_periodic_writes_documented_results_figures_and_paraview)."""
    from helpers.slow import weakly_held

    from fretwear.analyses.periodic import slow_verdict
    from fretwear.hb.fourier import FourierBasis
    from fretwear.hb.periodic import solve_periodic

    found = {}
    for kw in (1e-5, 1e-4, 0.1):
        model = weakly_held(kw)
        sol = solve_periodic(model, FourierBasis.up_to(15, 256), frequency=1.1 / (2 * np.pi),
                             time_domain=None, eps=10.0)
        found[kw] = slow_verdict(model, sol, None)
    line, attrs = found[1e-5]
    rho = attrs["slow_multiplier"]
    assert 1 - 1e-3 < rho < 1 and "mean tangential position is held only weakly" in line
    assert f"{1 / (1 - rho):.2g} periods" in line and "drifting" in line
    line, attrs = found[1e-4]
    assert line == "" and 1 - 1e-2 < attrs["slow_multiplier"] < 1 - 1e-3
    line, attrs = found[0.1]
    assert line == "" and np.isnan(attrs["slow_multiplier"])
