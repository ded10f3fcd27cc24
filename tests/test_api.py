"""The Python API (fretwear.api) refuses wrong shapes, types and values at its entry points
with a ValueError (InputError) or TypeError that names the argument, instead of a traceback
from deep inside (an AttributeError on None, an IndexError in the balance, a geomspace
error) or a silent answer (complex K cut to its real part, a zero response reported as converged).

Reference: the documented signatures (docstrings) of each entry point.
"""

import math

import numpy as np
import pytest
import scipy.sparse as sp

import fretwear as fw
from fretwear.errors import InputError
from fretwear.hb.options import SweepOptions
from fretwear.model import ContactSpec, Material, Spring, Traction, from_mesh, rectangle
from fretwear.model.core import Load
from fretwear.timedomain.options import InitialState, IntegrationOptions


@pytest.fixture(scope="module")
def block():
    return from_mesh(rectangle(0.02, 0.01, 4, 2), Material(210e9, 0.3, 7800.0), thickness=0.01,
                     supports=[Spring(at=(0.0, 0.005), direction="x", stiffness=1e7)],
                     loads=[Traction("top", pressure=1e6),
                            Traction("right", pressure=1e5, waveform="cos")],
                     contact=ContactSpec("bottom", mu=0.3), observed={"Pe": (0.02, 0.005)})


BASIS = fw.FourierBasis.up_to(3, 32)


@pytest.mark.parametrize("kw,match", [
    ({"frequency": -5.0}, "frequency"),
    ({"frequency": math.nan}, "frequency"),
    ({"frequency": 0.0}, "frequency = 0.0 Hz: expected > 0"),
    ({"frequency": 1e30}, "frequency"),
    ({"anchor": np.zeros((2, 2))}, "anchor has shape"),
    ({"U0": np.zeros(3)}, "U0 has shape"),
])
def test_solve_periodic_bad_values(block, kw, match):
    args = {"frequency": 1500.0, **kw}
    with pytest.raises(InputError, match=match):
        fw.solve_periodic(block, BASIS, **args)


def test_solve_periodic_bad_types(block):
    with pytest.raises(TypeError, match="model = None: expected a fretwear Model"):
        fw.solve_periodic(None, BASIS, frequency=1500.0)
    with pytest.raises(TypeError, match="basis = 3: expected a fretwear FourierBasis"):
        fw.solve_periodic(block, 3, frequency=1500.0)
    with pytest.raises(InputError, match="basis keeps no harmonic"):
        fw.solve_periodic(block, fw.FourierBasis.static(), frequency=1500.0)


def test_load_on_a_harmonic_that_is_not_kept_is_refused():
    """A load on harmonic 5 with harmonics 1..3 kept would give a static response reported
    as converged: refused, naming both."""
    m = from_mesh(rectangle(0.02, 0.01, 4, 2), Material(210e9, 0.3, 7800.0), thickness=0.01,
                  supports=[Spring(at=(0.0, 0.005), direction="x", stiffness=1e7)],
                  loads=[Traction("top", pressure=1e6),
                         Traction("right", pressure=1e5, waveform="fourier",
                                  coefficients={5: (1.0, 0.0)})],
                  contact=ContactSpec("bottom", mu=0.3))
    with pytest.raises(InputError, match=r"act on harmonics \[5\] but the basis keeps "
                                         r"\[1, 2, 3\]"):
        fw.solve_periodic(m, BASIS, frequency=1500.0)


@pytest.mark.parametrize("args,match", [
    ((0.0, 2e3, 5), "0 < f_min < f_max"),
    ((2e3, 1e3, 5), "0 < f_min < f_max"),
    ((1e3, 1e3, 5), "0 < f_min < f_max"),
    ((1e3, 2e3, 1), "n_points = 1: expected an integer >= 2"),
    ((1e3, 2e3, 2.5), "n_points = 2.5"),
    ((1e3, 2e3, 10**12), "needs about .* GiB of memory"),
    ((-1e3, 2e3, 5), "f_min"),
])
def test_sweep_bad_bands(block, args, match):
    with pytest.raises(InputError, match=match):
        fw.sweep(block, BASIS, *args)


def test_sweep_bad_spacing(block):
    with pytest.raises(InputError, match='spacing = .lin.: expected "log" or "linear"'):
        fw.sweep(block, BASIS, 1e3, 2e3, 3, options=SweepOptions(spacing="lin"))


@pytest.mark.parametrize("harmonics,samples,match", [
    ((1, 2.5), 16, "expected integers"),
    ((1,), 2.5, "n_samples = 2.5"),
    ((1,), 10**9, "needs about .* GiB of memory"),
])
def test_fourier_basis_bad_arguments(harmonics, samples, match):
    with pytest.raises(InputError, match=match):
        fw.FourierBasis(harmonics, samples)


def test_complex_stiffness_is_refused_not_cut():
    K = sp.csr_matrix(np.array([[2.0, -1.0], [-1.0, 2.0]]) * (1 + 0.01j))
    with pytest.raises(InputError, match="K holds complex values"):
        fw.from_matrices(K, sp.identity(2),
                         contact=fw.ContactDofs(normal_dofs=[0], tangential_dofs=[1], mu=0.3))


def test_nan_load_is_refused():
    K = sp.csr_matrix(np.array([[2.0, -1.0], [-1.0, 2.0]]))
    with pytest.raises(InputError, match="finite nodal forces"):
        fw.from_matrices(K, sp.identity(2),
                         contact=fw.ContactDofs(normal_dofs=[0], tangential_dofs=[1], mu=0.3),
                         loads=[Load(np.array([np.nan, 0.0]), "cos")])


def test_simulate_wear_checks_its_arguments(block):
    with pytest.raises(TypeError, match="options = .*expected a WearOptions"):
        fw.simulate_wear(block, BASIS, frequency=1500.0, options={"max_steps": 3})
    with pytest.raises(InputError, match="frequency"):
        fw.simulate_wear(block, BASIS, frequency=-1.0)
    with pytest.raises(InputError, match="max_steps"):
        fw.WearOptions(max_steps=2.5)


def test_time_integration_frequency(block):
    with pytest.raises(InputError, match="frequency"):
        fw.integrate(block, 1e30, n_periods=1)
    with pytest.raises(InputError, match="frequency"):
        fw.integrate(block, -1.0, n_periods=1)


def test_time_steps_that_cannot_be_recorded_are_refused(block):
    """1e9 steps per period recorded: refused with the memory estimate, before allocating."""
    with pytest.raises(InputError, match=r"recording 1 periods of 1000000000 time steps needs "
                                         r"about .* GiB"):
        fw.integrate(block, 1500.0, options=IntegrationOptions(steps_per_period=10**9), n_periods=1)


# --- one vocabulary and argument order (fretwear.api) -----------------------------------------
def test_frequency_is_required_where_it_matters(block):
    """A dynamic solve without a frequency is refused (it used to run at 1 Hz); a quasi-static
    one may go without (the frequency then only scales time); the frequency may be given by
    position, after (model, basis), with the same answer bit for bit."""
    for call in (lambda: fw.solve_periodic(block, BASIS),
                 lambda: fw.simulate_wear(block, BASIS, options=fw.WearOptions(max_steps=1))):
        with pytest.raises(InputError, match=r"frequency = None: expected the excitation "
                                             r"frequency \[Hz\]"):
            call()
    assert fw.solve_periodic(block, BASIS, quasi_static=True).success
    a = fw.solve_periodic(block, BASIS, 1500.0)
    b = fw.solve_periodic(block, BASIS, frequency=1500.0)
    assert a.success and a.frequency == 1500.0
    np.testing.assert_array_equal(a.U, b.U)


@pytest.mark.parametrize("call,old,new", [
    (lambda m, kw: fw.solve_periodic(m, BASIS, 1500.0, **kw), "stick_anchor", "anchor"),
    (lambda m, kw: fw.simulate_wear(m, BASIS, 1500.0, **kw), "W0", "wear0"),
    (lambda m, kw: fw.integrate(m, 1500.0, n_periods=1, **kw), "stick_anchor", "anchor"),
    (lambda m, kw: fw.steady_state(m, 1500.0, **kw), "stick_anchor", "anchor"),
    (lambda m, kw: fw.incremental_wear(m, **kw), "k_w", "wear_coefficient"),
    (lambda m, kw: fw.frf_worn(m, BASIS, 0.0, 1e3, 2e3, 2, **kw), "frequencies_hz",
     "f_min, f_max, n_points"),
])
def test_other_spellings_are_refused_with_the_public_one(block, call, old, new):
    with pytest.raises(TypeError, match=f"takes {new}, not {old}"):
        call(block, {old: None})


def test_public_names_reach_the_core(block):
    """``anchor`` of the initial state of fw.integrate reaches the time-domain solver (the
    same run bit for bit as the solver's own, and not the run without it);
    ``wear_coefficient`` of fw.incremental_wear is its own (0: no wear at all); ``wear0`` of
    fw.simulate_wear is the initial wear (the first row of the history)."""
    from fretwear.timedomain.integrate import integrate
    from fretwear.timedomain.quasistatic import incremental_wear

    nc = block.contact.n_nodes
    anchor = np.full((nc, 1), 1e-7)
    scheme = fw.IntegrationOptions(steps_per_period=16)
    a = fw.integrate(block, 1500.0, n_periods=1, options=scheme,
                     start=fw.InitialState(anchor=anchor))
    b = integrate(block, 1500.0, n_periods=1, options=scheme, start=InitialState(anchor=anchor))
    c = integrate(block, 1500.0, n_periods=1, options=scheme)
    np.testing.assert_array_equal(a.U, b.U)
    assert not np.array_equal(a.U, c.U)
    steps = fw.IncrementalWearOptions(steps_per_cycle=8)
    w = fw.incremental_wear(block, n_cycles=2, options=steps, wear_coefficient=0.0)
    assert w.k_w == 0.0 and not np.any(w.wear)
    assert np.array_equal(w.slip, incremental_wear(block, n_cycles=2, options=steps,
                                                   wear_coefficient=0.0).slip)
    wear0 = np.linspace(0.0, 1e-9, nc)
    r = fw.simulate_wear(block, BASIS, quasi_static=True, wear0=wear0,
                         options=fw.WearOptions(max_steps=1))
    np.testing.assert_array_equal(r.history.wear_depth[0], wear0)


def test_frf_worn_is_the_sweep_of_the_worn_gap(block):
    """fw.frf_worn(model, basis, wear, f_min, f_max, n_points) in the order of fw.sweep is
    fw.sweep with the gap opened by the wear and a linear grid (its definition, paper
    Fig. 24): the same solves, so the same amplitudes bit for bit. The former order
    (model, wear, (f_min, f_max, n_points), basis) is refused."""
    gap = np.broadcast_to(np.asarray(block.contact.gap, float), (block.contact.n_nodes,))
    wear = np.linspace(0.0, 2e-9, block.contact.n_nodes)
    a = fw.frf_worn(block, BASIS, wear, 1400.0, 1600.0, 2)
    b = fw.sweep(block, BASIS, 1400.0, 1600.0, 2, options=SweepOptions(spacing="linear"),
                 gap=gap + wear)
    assert a.success == b.success and a.point_success.any()
    np.testing.assert_array_equal(a.frequency_hz, b.frequency_hz)
    np.testing.assert_array_equal(a.amplitude("Pe", 0), b.amplitude("Pe", 0))
    with pytest.raises(TypeError):
        fw.frf_worn(block, wear, (1400.0, 1600.0, 2), BASIS)


def test_sweep_progress_bar_and_callable(block, capsys):
    """fw.sweep(..., progress=True) draws a bar (it raised "'bool' object is not callable");
    the bar only reports, so the answer is the same bit for bit as without it; a callable is
    called once per grid frequency with (i, n, point); anything else, or a progress given both
    as the keyword and in the options, is one InputError."""
    a = fw.sweep(block, BASIS, 1400.0, 1600.0, 3, progress=True)
    assert "sweep" in capsys.readouterr().err
    b = fw.sweep(block, BASIS, 1400.0, 1600.0, 3)
    np.testing.assert_array_equal(a.amplitude("Pe", 0), b.amplitude("Pe", 0))
    calls = []
    fw.sweep(block, BASIS, 1400.0, 1600.0, 3, progress=lambda i, n, p: calls.append((i, n)))
    assert calls == [(0, 3), (1, 3), (2, 3)]
    with pytest.raises(InputError, match="progress = 'yes': expected True, False or a callable"):
        fw.sweep(block, BASIS, 1400.0, 1600.0, 3, progress="yes")
    with pytest.raises(InputError, match="progress given twice"):
        fw.sweep(block, BASIS, 1400.0, 1600.0, 3, progress=True,
                 options=SweepOptions(progress=lambda *a: None))


@pytest.mark.parametrize("facade,core,own", [
    ("sweep", "fretwear.hb.sweep.sweep", {"time_domain", "progress"}),
    ("simulate_wear", "fretwear.wear.simulate.simulate_wear", {"progress", "condenser"}),
])
def test_first_drivers_have_real_signatures(facade, core, own):
    """fw.sweep and fw.simulate_wear show every option (they took **kwargs, so help() and an
    IDE showed nothing): no catch-all, the same keywords as the core function they call (the
    independent reference: its own signature) plus the facade's own, each named in the
    docstring."""
    import importlib
    import inspect

    func = getattr(fw, facade)
    params = inspect.signature(func).parameters
    assert not any(p.kind in (p.VAR_KEYWORD, p.VAR_POSITIONAL) for p in params.values())
    mod, name = core.rsplit(".", 1)
    core_params = set(inspect.signature(getattr(importlib.import_module(mod), name)).parameters)
    assert set(params) == core_params | own
    doc = inspect.getdoc(func)
    for p in set(params) - {"model", "basis"}:
        assert f"{p} :" in doc or f"{p}," in doc, f"fw.{facade}: {p} not documented"


def test_wear_progress_bar(block, capsys):
    """fw.simulate_wear(..., progress=True) draws the run's bar as fw.sweep does (it was a
    TypeError from the core function); the bar only reports, so the history is the same bit
    for bit; progress given twice, or not a bool, is one InputError."""
    opts = fw.WearOptions(max_steps=2)
    a = fw.simulate_wear(block, BASIS, quasi_static=True, options=opts, progress=True)
    b = fw.simulate_wear(block, BASIS, quasi_static=True, options=opts)
    assert capsys.readouterr().err
    np.testing.assert_array_equal(a.history.wear_depth, b.history.wear_depth)
    with pytest.raises(InputError, match="progress given twice"):
        fw.simulate_wear(block, BASIS, quasi_static=True, options=opts, progress=True,
                         run=fw.RunControl(progress=True))
    with pytest.raises(InputError, match="progress = 'yes': expected True or False"):
        fw.simulate_wear(block, BASIS, quasi_static=True, options=opts, progress="yes")


def test_sweep_amplitude_names_its_axes_and_points(block):
    """res.amplitude takes "x"/"y" as count_resonances does (it raised a raw IndexError):
    the named axis is the same component as its index, bit for bit; an unknown axis, point or
    harmonic is one InputError naming what there is."""
    res = fw.sweep(block, BASIS, 1400.0, 1600.0, 2)
    np.testing.assert_array_equal(res.amplitude("Pe", "x"), res.amplitude("Pe", 0))
    np.testing.assert_array_equal(res.amplitude("Pe", "Y"), res.amplitude("Pe", 1))
    with pytest.raises(InputError, match=r"axis = 'z': expected 'x', 'y' or an index 0\.\.1"):
        res.amplitude("Pe", "z")
    with pytest.raises(InputError, match="axis = 2"):
        res.amplitude("Pe", 2)
    with pytest.raises(InputError, match="no observed point 'tip'; the model observes: 'Pe'"):
        res.amplitude("tip", "x")
    with pytest.raises(InputError, match="harmonic = 5 is not kept"):
        res.amplitude("Pe", "x", harmonic=5)


def test_drivers_run_with_one_blas_thread_from_python(block):
    """From Python, as from the command line, the drivers run with one BLAS thread (a sweep
    was 3-16x slower from a notebook than from the CLI on a loaded 2-core machine): the BLAS
    thread count seen by threadpoolctl (independent of fretwear) inside the sweep is 1, the
    caller's setting is back after it, and set_blas_threads changes the count."""
    threadpoolctl = pytest.importorskip("threadpoolctl")

    def blas():
        return {i["num_threads"] for i in threadpoolctl.threadpool_info()
                if i["user_api"] == "blas"}

    seen = []
    before = blas()
    with threadpoolctl.threadpool_limits(limits=2, user_api="blas"):
        outside = blas()
        fw.sweep(block, BASIS, 1400.0, 1600.0, 2, progress=lambda *a: seen.append(blas()))
        assert blas() == outside
        try:
            fw.set_blas_threads(2)
            fw.sweep(block, BASIS, 1400.0, 1600.0, 2,
                     progress=lambda *a: seen.append(blas()))
        finally:
            fw.set_blas_threads(1)
    assert seen[:2] == [{1}, {1}] and seen[2:] == [outside, outside]
    assert blas() == before
    with pytest.raises(InputError, match=r"set_blas_threads\(0\)"):
        fw.set_blas_threads(0)


def test_subpackages_are_attributes_in_a_fresh_interpreter():
    """``fw.model.join``, ``fw.hb`` and ``fw.linear`` work right after ``import fretwear``
    (they raised AttributeError unless another name had loaded the submodule first): checked
    in a fresh interpreter, where nothing else has been imported."""
    import subprocess
    import sys

    code = ("import fretwear as fw; fw.model.join; fw.hb.__name__; fw.linear.frf; "
            "fw.wear.simulate_wear; print('ok')")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr


@pytest.mark.parametrize("driver", ["simulate_wear", "worn_state"])
def test_a_wear_run_that_cannot_wear_is_warned(block, driver, monkeypatch):
    """Archard coefficients all 0 (the contact's default, as in ``block``): the run stopped at
    once with "no wear ... success=True" and said nothing else; now an UnusualValueWarning
    names the key before the run, at the caller's line (not inside fretwear). With k_w > 0,
    or under the energy law (its own coefficient), no such warning. The core is replaced by
    a stub: only the check runs."""
    import warnings

    import fretwear.api
    from fretwear.limits import UnusualValueWarning

    core = {"simulate_wear": (fretwear.api._wear, "simulate_wear"),
            "worn_state": (fretwear.api, "_worn_state")}[driver]
    monkeypatch.setattr(*core, lambda *a, **k: "ran")
    call = getattr(fw, driver)
    with pytest.warns(UnusualValueWarning,
                      match=r"contact.wear_coefficient = 0 on every") as caught:
        assert call(block, BASIS, quasi_static=True) == "ran"
    assert caught[0].filename == __file__  # the user's call, past the driver's decorators
    worn = from_mesh(rectangle(0.02, 0.01, 4, 2), Material(210e9, 0.3, 7800.0),
                     thickness=0.01, supports=[Spring(at=(0.0, 0.005), direction="x",
                                                      stiffness=1e7)],
                     contact=ContactSpec("bottom", mu=0.3, wear_coefficient=1e-14))
    energy = fw.WearOptions(law="energy", energy_coefficient=1e-14)
    with warnings.catch_warnings():
        warnings.simplefilter("error", UnusualValueWarning)
        assert call(worn, BASIS, quasi_static=True) == "ran"
        opts = energy if driver == "simulate_wear" else fw.WornStateOptions(wear=energy)
        assert call(block, BASIS, quasi_static=True, options=opts) == "ran"
