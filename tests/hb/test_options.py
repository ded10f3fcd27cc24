"""The options records of the periodic solve and the sweep (:mod:`fretwear.hb.options`): bad
values are refused when a record is made, with one InputError naming the option (never a
solve that "fails" with success False); the presets differ from the defaults only where they
say so; the checkpoint keys of a record."""

import math

import numpy as np
import pytest

from fretwear.errors import InputError
from fretwear.hb.options import (
    KRYLOV,
    OTHER_SOLVER,
    PERIODIC,
    STRATEGY,
    SWEEP,
    SWEEP_POINT,
    WEAR_STEP,
    KrylovOptions,
    SolveOptions,
    SweepOptions,
    sweep_options,
)


@pytest.mark.parametrize("name, value", [
    ("tol", -1.0), ("tol", 0.0), ("tol", math.nan), ("tol", math.inf), ("tol", 1.0),
    ("tol", True), ("tol", "1e-8"), ("max_iter", 0), ("max_iter", 40.0), ("max_iter", True),
    ("solver", "newton?"), ("solver", None), ("jacobian", "sparse"),
    ("strategy", ()), ("strategy", ("start", "restart")), ("strategy", ("start", "start")),
    ("time_domain_periods", 0), ("time_domain_periods", 30.5), ("krylov", "single"),
    ("krylov", {"single": True}),
])
def test_solve_options_refuse_bad_values(name, value):
    with pytest.raises(InputError, match=f"^{name} = ") as err:
        SolveOptions(**{name: value})
    assert "\n" not in str(err.value)
    with pytest.raises(InputError, match=f"^{name} = "):
        PERIODIC.replace(**{name: value})


@pytest.mark.parametrize("name, value", [
    ("single_factors", 1), ("single_factors", "yes"), ("single_max_iterations", 0),
    ("single_max_iterations", 10.0), ("single_max_iterations", True),
    ("preconditioner", "ilu"), ("preconditioner", None), ("first_scales", 1),
    ("single_products", "no"), ("local_phase", 0), ("node_correction", 1),
    ("node_correction_min_dofs", -1), ("node_correction_min_dofs", 2048.0),
    ("compressed_products_min_dofs", 0), ("compressed_products_min_dofs", 1728.0),
    ("compressed_products_min_dofs", True),
])
def test_krylov_options_refuse_bad_values(name, value):
    with pytest.raises(InputError, match=f"^krylov.{name} = ") as err:
        KrylovOptions(**{name: value})
    assert "\n" not in str(err.value)
    with pytest.raises(InputError, match=f"^krylov.{name} = "):
        SolveOptions(krylov={name: value})


def test_krylov_options_are_a_field_of_the_solve_record():
    """The operator path's switches (single-precision factors, their bound, the
    preconditioner of compressed operators) are one record held by SolveOptions, a dict of its
    fields taken too; the defaults are those of every preset; a checkpoint key names them only
    when they differ from the preset's."""
    o = SolveOptions(krylov={"single_factors": False, "preconditioner": "nearfield"})
    assert o.krylov == KrylovOptions(single_factors=False, preconditioner="nearfield")
    assert PERIODIC.krylov is KRYLOV == KrylovOptions() and WEAR_STEP.krylov == KRYLOV
    assert KRYLOV.single_factors and KRYLOV.preconditioner == "mean-gain"
    assert "krylov" not in PERIODIC.key_changes(PERIODIC)
    assert o.key_changes(PERIODIC)["krylov"]["single_factors"] is False


def test_solve_options_accept_numpy_numbers_and_lists():
    o = SolveOptions(tol=np.float64(1e-10), max_iter=np.int64(5), strategy=["start"])
    assert o.strategy == ("start",) and o.max_iter == 5


def test_presets_differ_from_the_defaults_only_where_they_say():
    """One set of defaults: PERIODIC is the record's; the sweep point and the wear step change
    only their iteration cap, tolerance and (wear) the attempts of the first balance."""
    assert PERIODIC == SolveOptions()
    assert SWEEP_POINT == PERIODIC.replace(max_iter=40)
    assert WEAR_STEP == PERIODIC.replace(tol=1e-9, max_iter=60, strategy=("start",))
    assert PERIODIC.strategy == STRATEGY and SWEEP.solve == SWEEP_POINT


def test_other_solver_is_one_map():
    assert {s: SolveOptions(solver=s).other_solver for s in OTHER_SOLVER} == {
        "powell": "newton", "newton": "powell", "hybr": "powell"}


def test_key_changes_keep_the_keys_of_earlier_checkpoints():
    """The solve part of a checkpoint key: solver, tol, max_iter always, any other setting only
    when it differs from the preset (so a key written before that setting existed still
    matches)."""
    assert WEAR_STEP.key_changes(WEAR_STEP) == {"solver": "powell", "tol": 1e-9, "max_iter": 60}
    assert WEAR_STEP.replace(jacobian="dense").key_changes(WEAR_STEP)["jacobian"] == "dense"


@pytest.mark.parametrize("name, value", [
    ("spacing", "lin"), ("eps_band", (2.0, 1.0)), ("eps_band", "band"), ("continuation", 1),
    ("max_bisections", -1), ("flag", 3), ("progress", "bar"), ("time_domain", print),
    ("checkpoint", 3), ("resume", "yes"), ("solve", {"tol": 1e-8}),
])
def test_sweep_options_refuse_bad_values(name, value):
    with pytest.raises(InputError, match=f"^{name} = "):
        SweepOptions(**{name: value})


def test_sweep_options_of_a_solve_record():
    """A SolveOptions stands for the base sweep settings with that solve."""
    o = sweep_options(SWEEP_POINT.replace(tol=1e-10))
    assert o == SWEEP.replace(solve=SWEEP_POINT.replace(tol=1e-10))
    base = SWEEP.replace(spacing="linear")
    assert sweep_options(None, base) is base
    assert sweep_options(PERIODIC, base).spacing == "linear"
    assert SweepOptions(eps_band=[1, 2]).eps_band == (1.0, 2.0)
    with pytest.raises(InputError, match="options = "):
        sweep_options({"tol": 1e-8})
