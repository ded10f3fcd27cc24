"""One definition per option: the default of every case-file key that is a keyword of the
Python function its analysis calls is that keyword's default (the schema takes it from the
signature, :func:`fretwear.analyses.common.default_of`), and the default of a key that is a
field of an options record (:class:`~fretwear.hb.options.SolveOptions` and its presets,
:class:`~fretwear.hb.options.SweepOptions`) is that field's in the record the analysis runs
with.

The table below restates, independently of the schemas, which function and keyword (or which
record and field) each key maps to; the test validates minimal case files and compares the
filled-in defaults with the signatures and records, so it fails when either side is changed
alone.
"""

from __future__ import annotations

import inspect
from dataclasses import fields, is_dataclass

import pytest

from fretwear import api, linear
from fretwear.analyses.registry import analysis_tables
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.inputs import QUASI_STATIC_FREQUENCY
from fretwear.hb.nonlinear_modes import nonlinear_mode
from fretwear.hb.options import PERIODIC, SWEEP, WEAR_STEP, SolveOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.io.case import validate
from fretwear.timedomain.integrate import integrate
from fretwear.timedomain.options import (
    IncrementalWearOptions,
    IntegrationOptions,
    SteadyStateOptions,
)
from fretwear.timedomain.quasistatic import incremental_wear
from fretwear.timedomain.steady import steady_state
from fretwear.wear import BalanceSetup, WearOptions, simulate_wear
from fretwear.wear import simulate as wear_simulate
from fretwear.wear.worn_frf import WORN_FRF

MODEL = {"model": {"type": "box", "lx": 1.0, "ly": 1.0, "lz": 1.0, "nx": 1, "ny": 1, "nz": 1},
         "material": {"E": 1.0, "nu": 0.0}, "contact": {"boundary": "zmin", "mu": 0.1}}
BASIS = {"harmonics": (FourierBasis.up_to, "nh"), "n_samples": (FourierBasis.up_to, "n_samples")}
WEAR_OPTIONS = {f.name: f.default for f in fields(WearOptions)}

#: analysis type -> (required keys, {key: (function, keyword) or (record, field)})
CASES = {
    "modes": ({}, {"n_modes": (linear.modes, "n_modes")}),
    "frf": ({"f_min": 1.0, "f_max": 10.0},
            {"spacing": (linear.frequency_grid, "spacing"), "method": (linear.frf, "method")}),
    "periodic": ({"frequency": 10.0}, {
        **BASIS, **{k: (solve_periodic, k) for k in ("quasi_static", "eps")},
        **{k: (PERIODIC, k) for k in ("solver", "tol", "max_iter", "time_domain_periods")}}),
    "sweep": ({"f_min": 1.0, "f_max": 10.0}, {
        **BASIS, **{k: (SWEEP, k) for k in ("spacing", "continuation", "eps")},
        **{k: (SWEEP.solve, k) for k in ("time_domain_periods", "solver", "tol", "max_iter")},
        "time_domain": (api.sweep, "time_domain")}),
    "nonlinear-modes": ({"amplitude_min": 1e-6, "amplitude_max": 1e-3}, {
        **BASIS, "mode": (api.nonlinear_mode, "mode"),
        "interface": (api.nonlinear_mode, "interface"),
        **{k: (nonlinear_mode, k) for k in ("masters", "eps")},
        **{k: (SolveOptions, k) for k in ("solver", "tol", "max_iter")}}),
    "transient": ({"frequency": 10.0}, {
        "steps_per_period": (IntegrationOptions, "steps_per_period"),
        **{k: (SteadyStateOptions, k) for k in ("max_periods", "tol", "harmonics")}}),
    "incremental-wear": ({}, {
        "n_cycles": (incremental_wear, "n_cycles"),
        **{k: (IncrementalWearOptions, k) for k in (
            "steps_per_cycle", "cycle_jump", "record_every")}}),
    "wear": ({"frequency": 10.0, "frf_before_after": {"f_min": 1.0, "f_max": 10.0}}, {
        **BASIS, "quasi_static": (simulate_wear, "quasi_static"),
        "frf_before_after.spacing": (WORN_FRF, "spacing"),
        "frf_before_after.time_domain": (api.frf_worn, "time_domain")}),
}


def python_default(source, name):
    """The default of the keyword ``name`` of the function ``source``, or the field ``name``
    of the options record ``source``."""
    if is_dataclass(source):
        return getattr(source, name)
    return inspect.signature(source).parameters[name].default


def validated(kind: str, required: dict) -> dict:
    return validate({**MODEL, "analysis": {"type": kind, **required}},
                    analysis_tables())["analysis"]


@pytest.mark.parametrize("kind", list(CASES))
def test_case_file_defaults_are_the_python_defaults(kind):
    required, keys = CASES[kind]
    table = validated(kind, required)
    for key, (func, name) in keys.items():
        value = table
        for part in key.split("."):
            value = value[part]
        expected = python_default(func, name)
        assert value == expected and type(value) is type(expected), (
            f"[analysis] {kind}.{key} = {value!r}, {func!r:.40}: {name} = {expected!r}")


def test_wear_options_defaults():
    """Every wear option the table fills in has the default of WearOptions (None: not set, the
    key is then absent)."""
    table = validated("wear", {"frequency": 10.0})
    keys = analysis_tables()["wear"].fields
    assert "solve" not in keys and WEAR_OPTIONS["solve"] == WEAR_STEP
    for name in ("solver", "tol"):  # the keys of WearOptions.solve
        assert table[name] == getattr(WEAR_STEP, name), name
    for name, default in WEAR_OPTIONS.items():
        if name in table:
            assert table[name] == default, (name, table[name], default)
        elif name in keys:  # not written into the table: the option keeps its default
            assert default is None or name == "max_depth", name


def test_integrate_and_steady_state_share_their_step_and_frequency_defaults():
    """The transient analysis calls integrate (fixed) or steady_state: one default for the
    time scheme (the same IntegrationOptions, hence the same steps per period); and the
    frequency of a quasi-static solve (case files: 1 Hz) is one constant for the periodic
    solve and the wear run, which need a frequency only when dynamic."""
    assert python_default(integrate, "options") == python_default(steady_state, "integration")
    assert python_default(solve_periodic, "frequency") is None
    assert python_default(simulate_wear, "frequency") is None
    assert wear_simulate.QUASI_STATIC_FREQUENCY is QUASI_STATIC_FREQUENCY
    assert QUASI_STATIC_FREQUENCY == 1.0


def test_eps_words_not_none():
    """The penalty is spelt with the same words in Python and case files: no None default."""
    for source in (solve_periodic, SWEEP, WORN_FRF, BalanceSetup):
        assert python_default(source, "eps") in ("auto", "static", "top", "contact"), source
