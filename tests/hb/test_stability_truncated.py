"""Hill's candidates on a truncated interior (:func:`fretwear.hb.stability.truncated_structure`):
a problem of ``(m + q) H >= TRUNCATE_FROM`` unknowns forms its candidates' pencil on the
contact coordinates and the held structure's modes below the cutoff (Craig-Bampton), and
refines them on the exact ``T(s)``.

References, each independent of the truncated path: the dense eigensolve of the whole
structure's pencil (exact for a law without memory), the static condensation of the whole
stiffness, and the singular values of the exact ``T(s)`` formed at the refined exponents.
"""

import numpy as np
import pytest
import scipy.linalg as sla

from fretwear.hb import stability as st
from fretwear.hb.dynamics import structure_dynamics
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.reduce import exact_condenser
from fretwear.hb.stability import HillOptions, HillProblem, hill_stability, problem_of
from fretwear.model.beam import cantilever_matrices, modal_damping
from fretwear.model.build import Damping
from fretwear.model.core import Load
from fretwear.model.matrices import ContactDofs, from_matrices

BEAM = (0.71, 0.05, 0.06, 0.6725 * 210e9, 7850.0, 15)  # NLtest BT01's cantilever


def _unilateral_beam():
    """The cantilever (28 DOFs, 1 % modal damping) with its tip striking a unilateral spring
    (1e6 N/m, gap 0.1 mm; the tip's rotation a frictionless tangential DOF: no memory), 50 N
    at the tip: with contact springs the structure's DOFs are all interior (``q`` = 28, ``m``
    = 2), 420 unknowns of the pencil at 7 harmonics."""
    K, M = cantilever_matrices(*BEAM)
    n, tip = len(K), len(K) - 2
    f = np.zeros(n)
    f[tip] = 50.0
    model = from_matrices(K, M, contact=ContactDofs(normal_dofs=[tip], tangential_dofs=[tip + 1],
                                                    gap=1e-4, mu=0.0, kn=1e6, kt=1e6),
                          damping=Damping(C=modal_damping(K, M, 0.01)), loads=[Load(f, "cos")],
                          observed={"tip": tip})
    w1 = float(np.sqrt(sla.eigh(K, M, eigvals_only=True)[0]))
    return model, w1


def _jenkins_beam():
    """The virtual beam of benchmarks/nonlinear_modes.py (a Jenkins element, kt 1e7 N/m, mu N
    15 N, on node 6), 5 N at the tip: a law with memory."""
    K, M = cantilever_matrices(*BEAM)
    kt, dof = 1e7, 8
    e = np.zeros(len(K))
    e[dof] = 1.0
    f = np.zeros(len(K))
    f[len(K) - 2] = 5.0
    model = from_matrices(K, M, contact=ContactDofs(normal_dofs=None, tangential_dofs=[dof],
                                                    mu=15.0, normal_load=1.0, kt=kt),
                          damping=Damping(C=modal_damping(K + kt * np.outer(e, e), M, 0.01)),
                          loads=[Load(f, "cos")], observed={"tip": len(K) - 2})
    return model


def _solved(model, frequency, harmonics=7):
    cond = exact_condenser(model)
    sol = solve_periodic(model, FourierBasis.up_to(harmonics, 128), frequency=frequency)
    assert sol.success
    prob = problem_of(model, sol, condenser=cond)
    return prob, sol.U.reshape(prob.m, prob.H), structure_dynamics(model, cond)


def test_truncation_keeps_the_statics_and_the_held_modes():
    """The projected structure's static condensation on the contact coordinates equals the
    whole structure's, ``K_xx - K_xq K_qq^-1 K_qx`` (Craig-Bampton's constraint modes make it
    exact; dropping them, a planted fault, misses it by 1e-1 relative), and the kept
    modes are mass-normalised with ``K`` on them ``diag(w_j^2)`` (to rounding: 1e-9 of the
    largest, the eigensolver's own accuracy on a beam whose stiffness spans eight decades)."""
    model, w1 = _unilateral_beam()
    prob, U, dyn = _solved(model, 1.2 * w1 / (2 * np.pi))
    hp = HillProblem(prob, U, dyn)
    (K, M, C, D), r = hp.candidate_structure
    m, q = dyn.m, dyn.q
    assert hp.truncated and 0 < r < q
    Kf = hp._structure[0]

    def static(X, n):
        return X[:m, :m] - X[:m, m:n] @ np.linalg.solve(X[m:n, m:n], X[m:n, :m])

    ref = static(Kf, m + q)
    assert np.max(np.abs(static(K, m + r) - ref)) <= 1e-10 * np.max(np.abs(ref))
    w2, _ = dyn.held_modes
    assert np.allclose(M[m:, m:], np.eye(r), atol=1e-9)
    assert np.allclose(K[m:, m:], np.diag(w2[:r]), atol=1e-9 * w2[r - 1])


@pytest.mark.parametrize("ratio", [1.2, 1.4])
def test_truncated_candidates_refine_to_the_whole_pencils_exponents(ratio, monkeypatch):
    """A law without memory: the whole structure's pencil gives the exponents exactly (a dense
    eigensolve of 840 unknowns, kind "exact"); the truncated pencil (5 of 28 interior modes
    kept: 105) gives candidates within about 1e-4 of them, every one refined on the exact
    ``T(s)`` (whatever ``refine``): the same exponents to 1e-7 relative (each refinement
    stops at ``|mu| / |T| <= 1e-10``: measured 2e-8 and 2e-11), all of kind "refined", so
    the result is as reliable as the whole pencil's and its verdict the same."""
    model, w1 = _unilateral_beam()
    prob, U, dyn = _solved(model, ratio * w1 / (2 * np.pi))
    assert HillProblem(prob, U, dyn).memoryless()
    trunc = hill_stability(prob, U, dyn, options=HillOptions(track=False))
    monkeypatch.setattr(st, "TRUNCATE_FROM", 10**9)
    whole = hill_stability(prob, U, dyn, options=HillOptions(track=False))
    assert not HillProblem(prob, U, dyn).truncated
    assert set(whole.kind) == {"exact"} and set(trunc.kind) == {"refined"}
    assert trunc.spurious.size == 0 and trunc.exponents.size == whole.exponents.size >= 6
    for s in whole.exponents:
        assert np.min(np.abs(trunc.exponents - s)) <= 1e-7 * max(abs(s), whole.omega)
    assert trunc.reliable and trunc.stable == whole.stable


def test_a_failed_refinement_without_memory_stays_a_candidate(monkeypatch):
    """A cutoff far too low (a planted fault: 0.1 of the cut keeps one mode) leaves candidates
    whose refinement on ``T(s)`` does not converge. Without a memory such a candidate is an
    exponent moved by the truncation, not an artefact: it is reported as a candidate (not
    dropped as spurious), and the result says it is not reliable."""
    model, w1 = _unilateral_beam()
    prob, U, dyn = _solved(model, 1.4 * w1 / (2 * np.pi))
    monkeypatch.setattr(st, "HELD_CUTOFF", 0.1)
    fl = hill_stability(prob, U, dyn, options=HillOptions(track=False))
    assert HillProblem(prob, U, dyn).truncated
    assert fl.spurious.size == 0 and "candidate" in set(fl.kind)
    assert not fl.reliable


def test_refined_exponents_of_a_law_with_memory_are_zeros_of_the_exact_problem():
    """The virtual beam's Jenkins element sticks and slips (a memory): the truncated pencil
    (3 of 28 modes at 70 Hz) gives frozen-memory candidates; each refined exponent is a zero
    of the exact ``T(s)``: its smallest singular value, from an SVD of ``T`` formed anew
    (:meth:`HillProblem.matrix`), is below 1e-9 of its largest (the refinement's own stop is
    on ``|mu| / |T|`` of an LU: 1e-10)."""
    model = _jenkins_beam()
    prob, U, dyn = _solved(model, 70.0)
    hp = HillProblem(prob, U, dyn)
    assert hp.truncated and not hp.memoryless()
    fl = hill_stability(prob, U, dyn, options=HillOptions(track=False))
    refined = fl.exponents[fl.kind == "refined"]
    assert refined.size >= 2
    for s in refined:
        sv = np.linalg.svd(hp.matrix(s / fl.omega), compute_uv=False)
        assert sv[-1] <= 1e-9 * sv[0]


def test_a_modal_condensers_interior_is_not_truncated():
    """The same structure marked as a modal condenser's (``exact`` False: fixed-interface
    modes and residual vectors, whose truncation gave a doubtful refined exponent on the
    dovetail, docs/studies/dovetail-fold-stability.md) keeps its whole interior, while the
    exact one is truncated (the comparison that makes the test able to fail)."""
    model, w1 = _unilateral_beam()
    prob, U, dyn = _solved(model, 1.2 * w1 / (2 * np.pi))
    hp = HillProblem(prob, U, dyn)
    k = hp.harmonics.size
    assert st.truncated_structure(hp._structure, dyn, prob.H, k, hp.omega)[1] < dyn.q
    modal = type(dyn)(dyn.blocks, dyn.load_x, dyn.load_q, False)
    assert st.truncated_structure(hp._structure, modal, prob.H, k, hp.omega)[1] == dyn.q
