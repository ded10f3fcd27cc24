"""The static contact problem under the preload (:mod:`fretwear.hb.preload`), whose tangential
positions are the default stick anchors: a failed static solve is reported, never silent.
"""

import numpy as np
import pytest
import scipy.sparse as sp

from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.model.core import Load


def _pushed_oscillator(ratio):
    """The friction oscillator without its tangential spring, under a constant tangential load
    ``ratio mu N0``: for ratio > 1 no static equilibrium exists (Coulomb: |T| <= mu N0 and
    nothing else resists T), for ratio < 1 the node sticks where it is (anchor 0)."""
    from tests.helpers.models import KN, MU, N0, oscillator

    model = oscillator()
    model.K = sp.csr_matrix(np.diag([KN, 0.0]))
    model.loads[0] = Load(np.array([N0, ratio * MU * N0]), "constant")
    return model


def test_a_failed_static_preload_solve_is_reported_not_silent():
    """The static problem under the preload has no solution (a tangential load of twice the
    friction limit and no tangential stiffness, Coulomb's law): the anchors fall back to 0 and
    every result that uses them says so (preload_anchor, static_anchor's RuntimeWarning,
    solve_periodic's ``warnings``). Below the friction limit (0.5 mu N0) the same model has a
    static equilibrium and no warning is raised: the report depends on the solve. (Without a
    tangential spring and with a harmonic load above the friction limit neither model has a
    periodic state that stays put; only the report is checked here.)"""
    from fretwear.hb.preload import preload_anchor, static_anchor

    basis = FourierBasis.up_to(1, 16)
    bad = _pushed_oscillator(2.0)
    pre = preload_anchor(bad)
    assert not pre.success and np.array_equal(pre.values, np.zeros((1, 1)))
    assert pre.warning.startswith("the static contact problem under the preload did not "
                                  "converge (") and "stick anchors are set to 0" in pre.warning
    with pytest.warns(RuntimeWarning, match="did not converge"):
        assert np.array_equal(static_anchor(bad), np.zeros((1, 1)))
    sol = solve_periodic(bad, basis, frequency=15.0, options=SolveOptions(strategy=("start",)))
    assert sol.warnings == [pre.warning]
    # explicit anchors: no static solve, nothing to report
    assert solve_periodic(bad, basis, frequency=15.0, options=SolveOptions(strategy=("start",)),
                          anchor=np.zeros((1, 1))).warnings == []

    good = _pushed_oscillator(0.5)
    pre = preload_anchor(good)
    assert pre.success and pre.warning == ""
    np.testing.assert_allclose(pre.values, 0.0, atol=1e-12)  # stuck where it touched
    assert solve_periodic(good, basis, frequency=15.0,
                          options=SolveOptions(strategy=("start",))).warnings == []
