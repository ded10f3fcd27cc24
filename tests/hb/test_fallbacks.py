"""Fallbacks said as they happen and summed up with their cost (fretwear.hb.fallbacks).

References: the two-DOF chain of tests/hb/test_attempts.py, whose ladder is known to run
"start", "best-point" and "eps-continuation" (so two lines must be said, in that order, and
the fallback time is the ladder's time after the first attempt, below the solve's wall time);
the cost of hand-made histories and points counted by hand.
"""

import logging
from types import SimpleNamespace

import numpy as np
import pytest

from fretwear.hb import fallbacks
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.solution import Attempt


def _chain():
    from fretwear.model.build import Damping
    from fretwear.model.core import Load
    from fretwear.model.matrices import ContactDofs, from_matrices

    return from_matrices(np.array([[2.0, -1.0], [-1.0, 1.0]]), np.eye(2),
                         contact=ContactDofs(normal_dofs=None, tangential_dofs=[1], mu=0.5,
                                             normal_load=1.0),
                         damping=Damping(C=0.02 * np.eye(2)),
                         loads=[Load(np.array([0.2, 0.0]), "cos")], observed={"x": 0})


def test_each_rung_is_said_as_it_starts_and_its_time_counted(caplog):
    model = _chain()
    with caplog.at_level(logging.INFO, logger="fretwear"):
        sol = solve_periodic(model, FourierBasis.up_to(15, 128),
                             frequency=1.4905405 / (2 * np.pi), eps=1.0)
    assert sol.success and [a.method for a in sol.attempts] == [
        "start", "best-point", "eps-continuation"]
    said = [r.getMessage() for r in caplog.records if r.name == "fretwear"]
    assert len(said) == 2
    assert said[0].startswith("periodic solve at 0.237227 Hz: start failed")
    assert said[0].endswith("trying best-point")
    assert said[1].endswith("best-point failed (best residual "
                            f"{min(a.residual for a in sol.attempts[:2]):.2e}); trying "
                            "eps-continuation")
    assert 0.0 < sol.fallback_seconds < sol.stats.wall_time
    cost = fallbacks.of_solutions([sol], sol.stats.wall_time)
    assert cost.count == 1 and cost.time_domain == 0
    assert cost.seconds == pytest.approx(sol.fallback_seconds)


def _attempts(*methods):
    return [Attempt(m, "powell", 1.0, i == len(methods) - 1, 0.0, 1, 0.1, "")
            for i, m in enumerate(methods)]


def test_cost_of_points_and_of_a_wear_history():
    points = [SimpleNamespace(attempts=_attempts("grid"), fallback_seconds=0.0),
              SimpleNamespace(attempts=_attempts("grid", "retry"), fallback_seconds=2.0),
              SimpleNamespace(attempts=_attempts("grid", "time-start"), fallback_seconds=5.0)]
    cost = fallbacks.of_solutions(points, total=10.0)
    assert (cost.count, cost.time_domain, cost.seconds) == (2, 1, 7.0)
    hint = fallbacks.eps_hint(False)
    assert cost.line("frequencies", hint) == (
        "fallbacks: 2 frequencies needed more than their first attempt, 1 from a time "
        f"integration: 7.0 s (70 % of 10.0 s); {hint}")
    assert fallbacks.eps_hint(True) == ""
    wear = fallbacks.of_wear([0, 2, 2, 1, 0], [1.0, 30.0, 40.0, 5.0, 1.0], total=80.0)
    assert (wear.count, wear.seconds) == (3, 75.0)
    assert "eps =" not in wear.line("slow steps", "")
    small = fallbacks.of_wear([0, 1], [9.0, 1.0], total=100.0)
    assert small.line("slow steps", hint).endswith("1.0 s (1 % of 100.0 s)")  # no hint < 20 %
    assert fallbacks.FallbackCost().line() == ""



def test_wear_summary_says_where_no_periodic_response_exists():
    """A wear run whose slow steps took their rate from time integrations that found no
    periodic response (the paper's beam at 70 kHz: quasi-periodic, code 3 of
    RESPONSE_KINDS, at every step) is told so, not given a penalty to try that cannot find
    what the structure does not have; where some steps' integrations ran out of periods before
    they settled (code 5, transient), the hint stays beside the count of those that did not. The
    codes are those of fretwear.timedomain.averaged_rate.RESPONSE_KINDS (checked here)."""
    from fretwear.timedomain.averaged_rate import RESPONSE_KINDS

    assert [RESPONSE_KINDS[k] for k in fallbacks.NOT_PERIODIC] == [
        "subharmonic", "drifting", "quasi-periodic", "irregular"]
    hint = fallbacks.eps_hint(False)
    none = fallbacks.of_wear([0, 2, 2, 2], [1.0, 30.0, 40.0, 5.0], 80.0, [-1, 3, 3, 3])
    line = none.line("slow steps", hint)
    assert (none.count, none.no_periodic) == (3, 3)
    assert "eps =" not in line
    assert line.endswith("the structure has no periodic response at them (a time "
                         "integration found none)")
    some = fallbacks.of_wear([0, 2, 2], [1.0, 30.0, 40.0], 80.0, [-1, 5, 4])  # 5: transient
    assert some.line("slow steps", hint).endswith(
        f"no periodic response at 1 of them (a time integration found none); {hint}")

def test_halved_steps_and_arclength_are_the_sweeps_path_not_fallbacks():
    """The time of the rungs of fallbacks.CONTINUATION after the first attempt (halved steps,
    the arclength past a fold: the sweep's own path) is counted apart from the fallbacks and
    said on its own line; a point that needed only these is not a fallback; one that also
    tried another solver (retry) or a time integration is, with the rest of its time. Counted
    by hand on made-up points (attempts of 0.1 s, the arclength's 9 s: a fold crossed after a
    failed retry, as the shipped dovetail's)."""
    def tried(*rungs):
        return [Attempt(m, "powell", 1.0, i == len(rungs) - 1, 0.0, 1, t, "")
                for i, (m, t) in enumerate(rungs)]

    points = [SimpleNamespace(attempts=_attempts("grid", "substep"), fallback_seconds=1.0),
              SimpleNamespace(attempts=_attempts("grid", "arclength"), fallback_seconds=3.0),
              SimpleNamespace(attempts=_attempts("grid", "arclength", "time-start"),
                              fallback_seconds=4.0),
              SimpleNamespace(attempts=_attempts("grid", "retry"), fallback_seconds=2.0),
              SimpleNamespace(attempts=tried(("grid", 0.1), ("retry", 0.5), ("arclength", 9.0)),
                              fallback_seconds=10.0)]
    cost = fallbacks.of_solutions(points, total=40.0)
    assert (cost.count, cost.time_domain) == (3, 1)
    assert cost.seconds == pytest.approx(3.9 + 2.0 + 1.0)
    assert cost.continued == 2
    assert cost.continued_seconds == pytest.approx(1.0 + 3.0 + 0.1 + 9.0)
    assert cost.continuation_line() == (
        "continuation (halved steps, arclength past a fold: the sweep's own path, not "
        "fallbacks): 13.1 s (33 % of 40.0 s); 2 frequencies needed nothing else")
    only = fallbacks.of_solutions(points[:2], total=20.0)
    assert only.line("frequencies") == "" and only.continued == 2
    assert fallbacks.FallbackCost().continuation_line() == ""


def test_a_jump_at_a_fold_is_the_sweeps_path_and_listed_in_the_summary():
    """A point reached by a jump from a fold (``"jump"``, fretwear.hb.attempts.jump: the
    arclength turned back short of the frequency, as on the platform damper's FRF at
    38476.5 Hz) needed only the sweep's own path: not a fallback, and the continuation line
    lists where the jump left the branch and where it landed. Counted by hand on made-up
    points; a jump that failed is not listed (its point fell back). The fold's frequency is the
    attempt's own field (``from_hz``), not read back from its message."""
    ok = [Attempt("grid", "powell", 1.0, False, 0.1, 40, 0.1, ""),
          Attempt("arclength", "powell", 1.0, False, 0.1, 40, 5.0, ""),
          Attempt("jump", "powell", 1.0, True, 1e-14, 27, 0.2, "converged", 38476.5)]
    failed = [*ok[:2], Attempt("jump", "powell", 1.0, False, 0.04, 56, 0.2,
                               "not converged", 0.1214),
              Attempt("eps-continuation", "powell", 1.0, True, 1e-13, 3, 1.0, "")]
    points = [SimpleNamespace(frequency_hz=41016.8, attempts=ok, fallback_seconds=5.3),
              SimpleNamespace(frequency_hz=0.1225, attempts=failed, fallback_seconds=6.5)]
    cost = fallbacks.of_solutions(points, total=20.0)
    assert (cost.count, cost.continued) == (1, 1)
    assert cost.jumps == ["38476.5 Hz -> 41016.8 Hz"]
    assert cost.continuation_line().endswith(
        "1 frequencies needed nothing else; jumps at folds: 38476.5 Hz -> 41016.8 Hz")


def test_a_jump_resumed_from_an_earlier_checkpoint_is_listed():
    """A sweep checkpoint written before ``Attempt.from_hz`` existed (the same format
    version: its jump's record has no ``from_hz``) resumes to the same continuation line as
    the run that wrote it (the fold's frequency read back from the message, as that run did),
    and a jump with no fold frequency at all is listed as from "a fold": the summary once
    raised a TypeError on formatting None. Counted by hand, as above."""
    import dataclasses

    from fretwear.hb.branch import rebuild_point
    from fretwear.hb.solvers import SolveStats

    st = SolveStats(True, 1e-14, 27, 30, 3, 0.2, "converged", "powell")
    old = {"method": "jump", "solver": "powell", "eps": 1.0, "success": True,
           "residual": 1e-14, "iterations": 27, "wall_time": 0.2,
           "message": "converged (from the fold at 38476.5 Hz)"}
    rec = {"frequency_hz": 41016.8, "how": "jump", "flags": [], "on_grid": True,
           "time_domain": None, "stats": dataclasses.asdict(st),
           "attempts": [{**old, "method": "arclength", "success": False, "message": ""}, old]}
    pt = rebuild_point(None, {"record": rec})  # not converged here: no solution to assemble
    assert pt.attempts[1].from_hz == 38476.5
    bare = SimpleNamespace(frequency_hz=0.1225, attempts=[
        Attempt("grid", "powell", 1.0, False, 0.1, 40, 0.1, ""),
        Attempt("jump", "powell", 1.0, True, 1e-14, 27, 0.2, "converged")])
    cost = fallbacks.of_solutions([pt, bare], total=20.0)
    assert cost.jumps == ["38476.5 Hz -> 41016.8 Hz", "a fold -> 0.1225 Hz"]
