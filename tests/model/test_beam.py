"""Euler-Bernoulli cantilever matrices (:mod:`fretwear.model.beam`).

References: the clamped-free beam's natural frequencies of continuum theory,
``w_k = (beta_k L)^2 sqrt(EI / (rho A L^4))`` with ``beta_k L`` the roots of
``cos x cosh x = -1`` (1.8751, 4.6941, 7.8548); the static tip deflection ``F L^3 / (3 EI)``
(exact for cubic Hermite elements, whose shape functions contain the cubic deflection).
"""

import numpy as np
import pytest
import scipy.linalg as sla
from scipy.optimize import brentq

from fretwear.errors import InputError
from fretwear.model.beam import cantilever_matrices, modal_damping

L, H, T, E, RHO = 0.71, 0.05, 0.06, 0.6725 * 210e9, 7850.0


def test_tip_deflection_is_exact():
    """Hermite elements reproduce the cubic static deflection exactly: to rounding."""
    K, _ = cantilever_matrices(L, H, T, E, RHO, 5)
    f = np.zeros(len(K))
    f[-2] = 100.0
    EI = E * T * H ** 3 / 12
    assert np.linalg.solve(K, f)[-2] == pytest.approx(100.0 * L ** 3 / (3 * EI), rel=1e-12)


def test_frequencies_converge_to_the_continuum():
    """15 nodes: the first three frequencies within the discretisation error of cubic
    elements (measured 2.2e-7, 8.7e-6, 6.8e-5, above the continuum as a consistent mass
    gives; the bounds allow about 4x), and the error falls with refinement (8 nodes:
    3.5e-6, 1.4e-4, 1.0e-3, about h^4)."""
    EI, rhoA = E * T * H ** 3 / 12, RHO * T * H
    roots = [brentq(lambda x: np.cos(x) * np.cosh(x) + 1, a, a + 1.5)
             for a in (1.0, 4.0, 7.0)]
    exact = np.array(roots) ** 2 * np.sqrt(EI / (rhoA * L ** 4))
    errs = []
    for n in (8, 15):
        K, M = cantilever_matrices(L, H, T, E, RHO, n)
        w = np.sqrt(sla.eigh(K, M, eigvals_only=True)[:3])
        errs.append(w / exact - 1)
    assert np.all((errs[1] > 0) & (errs[1] < np.array([1e-6, 3e-5, 3e-4])))
    assert np.all(errs[1] < errs[0] / 10)


def test_modal_damping_gives_every_mode_its_ratio():
    """Projected on the mass-normalised modes, C is diagonal with 2 zeta w (to rounding)."""
    K, M = cantilever_matrices(L, H, T, E, RHO, 6)
    C = modal_damping(K, M, 0.01)
    w2, phi = sla.eigh(K, M)
    Cm = phi.T @ C @ phi
    assert np.allclose(Cm, np.diag(0.02 * np.sqrt(w2)), atol=1e-9 * Cm.max())


@pytest.mark.parametrize("kw", [{"length": -1.0}, {"n_nodes": 1}, {"n_nodes": 2.0}])
def test_bad_input_is_one_input_error(kw):
    args = dict(length=L, height=H, thickness=T, E=E, rho=RHO, n_nodes=5) | kw
    with pytest.raises(InputError, match=next(iter(kw))):
        cantilever_matrices(**args)
