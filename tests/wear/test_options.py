"""WearOptions: the one definition of the wear options and their defaults (case files take
theirs from it), checked when it is made."""

from __future__ import annotations

import math
from dataclasses import fields, replace

import numpy as np
import pytest

from fretwear.analyses.registry import get
from fretwear.analyses.wear import OPTION_KEYS, options_from_table
from fretwear.errors import InputError
from fretwear.hb.options import WEAR_STEP
from fretwear.io.schema import Context
from fretwear.wear import WearOptions


def validated(table: dict) -> dict:
    """The ``[analysis]`` table of ``type = "wear"`` as a case file gets it (defaults filled)."""
    return get("wear").schema.check(table, "analysis", Context())


def test_case_file_defaults_are_those_of_wear_options():
    """A case file that sets no wear option runs with WearOptions(): every wear option in the
    validated table has WearOptions' default, field by field, and the absent ones are exactly
    those without a value ("not set" or no limit), which keep WearOptions' default."""
    a = validated({"quasi_static": True})
    default = WearOptions()
    compared = 0
    for f in fields(WearOptions):
        if f.name in a:
            assert a[f.name] == getattr(default, f.name), f.name
            assert type(a[f.name]) is type(getattr(default, f.name)), f.name
            compared += 1
    for k in ("solver", "tol"):  # the keys of its solve record (WearOptions.solve)
        assert a[k] == getattr(default.solve, k), k
        assert type(a[k]) is type(getattr(default.solve, k)), k
        compared += 1
    assert compared == len(OPTION_KEYS) - 5
    assert {k for k in OPTION_KEYS if k not in a} == {
        "energy_coefficient", "partner_energy_coefficient", "initial_jump", "max_depth",
        "time_domain_steps"}
    assert default.max_depth == math.inf
    assert all(getattr(default, k) is None
               for k in ("energy_coefficient", "partner_energy_coefficient", "initial_jump",
                         "time_domain_steps"))
    assert options_from_table(a) == default


def test_every_wear_key_of_a_case_file_reaches_wear_options():
    """Each wear option set in a case file (to a value other than its default) arrives in the
    WearOptions of the run, and no other option changes."""
    given = {
        "solver": "hybr", "tol": 1e-10, "law": "energy", "energy_coefficient": 2e-13,
        "partner_energy_coefficient": 3e-13,
        "scheme": "implicit", "adaptive": False, "tolerance": 3e-3, "initial_jump": 50.0,
        "max_jump": 1e7, "max_cycles": 2e8, "max_depth": 1e-6, "plateau_rate": 1e-2,
        "max_steps": 77, "time_domain_rescue": False, "time_domain_settle": 11,
        "time_domain_average": 13, "time_domain_steps": 256, "checkpoint_every_s": 0.0,
    }
    assert set(given) == set(OPTION_KEYS)
    opts = options_from_table(validated({"quasi_static": True, **given}))
    default = WearOptions()
    for f in fields(WearOptions):
        expected = given.get(f.name, getattr(default, f.name))
        if f.name == "solve":  # the keys of its record: solver and tol
            expected = WEAR_STEP.replace(solver=given["solver"], tol=given["tol"])
            assert expected != default.solve
        assert expected != getattr(default, f.name) or f.name not in given, f.name
        assert getattr(opts, f.name) == expected, f.name


@pytest.mark.parametrize("name, value", [
    ("max_steps", 2.5), ("max_steps", 0), ("max_steps", True), ("solve", {"max_iter": 60}),
    ("max_iter_coupled", 0), ("max_iter_implicit", -1), ("max_retries", 1.5),
    ("time_domain_settle", 300.0), ("time_domain_average", 1), ("time_domain_steps", 4),
    ("time_domain_steps", 256.0), ("adaptive", 1), ("time_domain_rescue", "yes"),
    ("tolerance", 0.0), ("tolerance", "1e-2"), ("max_cycles", math.nan), ("max_jump", -1.0),
    ("min_jump", 0), ("max_depth", None), ("solve", None), ("plateau_rate", -1e-3),
    ("checkpoint_every_s", -1.0), ("initial_jump", 0.0), ("initial_jump", "1e4"),
    ("energy_coefficient", -1e-13), ("partner_energy_coefficient", -1e-13), ("law", "usui"),
    ("scheme", "rk4"), ("implicit_newton", "full"),
])
def test_wear_options_refuse_bad_values_when_made(name, value):
    """A wrong type or value is refused at construction (and by dataclasses.replace), with an
    InputError (a ValueError) that names the option."""
    with pytest.raises(InputError, match=name) as err:
        WearOptions(**{name: value})
    assert isinstance(err.value, ValueError)
    with pytest.raises(InputError, match=name):
        replace(WearOptions(), **{name: value})


def test_wear_options_accept_numbers_of_any_numeric_type():
    """Python and numpy integers where whole numbers are expected, integers where real numbers
    are (only booleans and floats are refused for counts)."""
    o = WearOptions(max_steps=np.int64(5), max_cycles=10**6, tolerance=np.float64(0.05),
                    time_domain_steps=512, initial_jump=100, max_depth=math.inf)
    assert o.max_steps == 5 and o.max_cycles == 1e6 and o.check() is o


def test_partner_energy_coefficient_needs_the_energy_law():
    with pytest.raises(InputError, match=r"^analysis.partner_energy_coefficient = 1e-13: "
                                         r"expected no value with law = \"archard\""):
        validated({"quasi_static": True, "partner_energy_coefficient": 1e-13})
