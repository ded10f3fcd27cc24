"""Stability of a periodic DLFT solution by Hill's method (Floquet exponents in the frequency
domain), on the balance's own linearisation.

The perturbation and its Floquet form
-------------------------------------
A small perturbation of a periodic solution of period ``T = 2 pi / w`` grows or decays as
``e^{s t} p(t)`` with ``p`` periodic: ``s`` is a Floquet exponent, ``rho = e^{s T}`` the
multiplier, and the solution is asymptotically stable when every ``|rho| < 1``. Written on the
balance's unknowns, ``p`` has the kept harmonics and ``T(s) p~ = 0`` with (docs/theory.md,
"Stability of periodic solutions")

    T(s) = eps I - G(s) (eps I - Z(s))

the DLFT Jacobian (``J = T(0)``, eq. 22-28 differentiated) with two changes:

* ``Z(s)``: harmonic ``n`` of ``e^{st} p`` oscillates at ``lambda = s +- i n w``, so its block
  is built from ``Z_r(s + i n w)`` and ``Z_r(s - i n w)`` (:mod:`fretwear.hb.dynamics`; at
  ``s = 0`` they are conjugate and give the real blocks ``[[Zr, Zi], [-Zi, Zr]]`` of the
  balance). ``Z_r`` is a condensation (a Schur complement), not a quadratic polynomial in
  ``s``.
* ``G(s)``: the law's derivative with a memory. Where a node sticks it carries the correction
  of the previous instant; for the perturbation, ``delta lambda_x(n) = delta lambda_x(n-1)``,
  i.e. ``r(n) = z r(n-1)`` for the periodic part ``r`` with ``z = e^{-s h}``, ``h = T / N``
  the sample step (and likewise for the carried part of a 3D slip). :func:`shifted_gain` is
  the recursion of :func:`fretwear.hb.contact.dlft_jacobian` with that factor; ``G(0)`` is the
  solve's own ``G``. A frozen ``G`` (``z = 1`` for every ``s``, the usual Hill method for a
  law without memory) is exact at ``s = 0`` only: a node that sticks from ``t0`` to ``t``
  remembers ``e^{-s (t - t0)}``, which is far from 1 when ``|s| T`` is not small.

The exponents are thus the roots of a nonlinear eigenvalue problem ``T(s) p~ = 0``, exact for
the truncated (DLFT-discretised) periodic solution.

How they are computed
---------------------
1. **Candidates**: on the structure's coordinates ``(x, q)`` (:mod:`fretwear.hb.dynamics`:
   the contact points and everything else, nothing condensed) the structure is exactly
   quadratic in ``s``; with the law's memory frozen (``G(s) = G(0)``) Hill's matrix is the
   polynomial ``A0 + sigma A1 + sigma^2 A2`` in ``sigma = s / w`` (:meth:`HillProblem.pencil`),
   whose eigenvalues are computed densely (:func:`quadratic_eigen`: massless coordinates
   eliminated, the blocks the problem decouples into solved apart, a standard eigenvalue
   problem of twice each block's size). Where no node sticks (nor
   slips in 3D) and the structure is exact, they are the exponents. On a large structure
   (:data:`TRUNCATE_FROM` unknowns ``(m + q) H``) the interior is first truncated to the
   modes of the structure with its contact points held below twice the magnitude cut and
   the static constraint modes (Craig-Bampton, :func:`truncated_structure`): the modes above
   only give exponents beyond the cut, and the candidates of the truncated pencil are
   refined on the exact ``T(s)`` as those of a law with memory are (step 3) (on the virtual
   beam of benchmarks/nonlinear_modes.py, 28 DOFs at 7 harmonics, the pencil 420 -> 60
   unknowns: a point's Hill 180 -> 8-11 ms with the condensation through the held modes).
   Only on an exact interior (the structure's own coordinates): a modal condenser's is kept
   whole (:func:`truncated_structure`).
2. **Sorting**: the truncated Hill problem has, for every exponent ``s``, copies
   ``s + i j w`` with the eigenvectors ``p e^{-i j w t}``, accurate only while the shifted
   eigenvector still fits in the kept harmonics. Each eigenvector has a harmonic centroid
   ``kappa`` (:func:`centroid`), and a copy shifted by ``j`` has ``kappa - j``: keeping
   ``|kappa| <= 1/2`` picks one member per family, the one centred on the kept harmonics and
   therefore the least truncated. The usual alternative (``|Im s| <= w/2``) also picks one
   member per family but, for a mode far above ``w``, the member whose eigenvector sits
   ``j`` harmonics off centre, where the truncation acts. At ``Im s = +-w/2`` (a real negative
   multiplier) the two members tie and count once (:data:`EDGE_TOL`).
3. **Refinement** (a node sticks: the memory matters; or the pencil was truncated): in
   decreasing order of their real
   parts, candidates are refined on the exact ``T(s)`` (condensed on the contact points,
   ``m H`` unknowns) until ``options.refine`` have converged (:func:`_track`: the secant
   method on the eigenvalue of ``T(s)`` whose eigenvector continues the candidate's,
   followed by inverse iteration on one LU per evaluation, :func:`_pair`; it stops when
   ``|mu| / |T|`` and ``|T v - mu v| / |T|`` are both below ``options.newton_tol``). A
   candidate near which the exact problem has no exponent is an artefact of the frozen memory
   (:attr:`FloquetResult.spurious`).
4. **Along a sweep** (``previous``: the neighbouring point's result), the candidates of step 1
   are continued from the neighbour's by inverse iteration on the quadratic problem
   (:func:`track_eigen`; Ruhe's steps, the last ones on a kept LU where a step has landed
   within 1e-4, ended by the pair's backward error at rounding, :func:`_ruhe`; each from the
   neighbour's eigenvalue moved by its secant velocity, a quadratic through three points
   measured no better: 6e-4 instead of 1.5e-3 off, not the 1e-4 that saves an LU) instead
   of its dense eigensolve, where that is shown to give the same set: the same contact
   regime (:meth:`HillProblem.regime`), every family represented at the neighbour and here
   (they number ``2 nd / H``), each member
   converged with ``|kappa| <= 1/2``, and its neighbouring copy on the side of the tie
   outside ``|kappa| <= 1/2``. On and near the period-doubling line (:func:`_on_line`) the mirror
   ``conj(s) + i`` of a member is checked too: there the two real negative multipliers of a
   period doubling are two simple eigenvalues ``a + i/2``, ``b + i/2``, each continued
   alone; where a complex pair lands on the line the mirror search may find the second one,
   and where the two meet into a complex pair they converge to one member. Otherwise (a
   jump between branches, a pair landing on the line whose second member is not found, a
   node leaving full stick) the dense eigensolve. A continued
   candidate's refinement starts from the neighbour's refined exponent with its last secant
   slope (:func:`_warm_start`; same stopping rule, from the candidate if it fails).

Exponents not reported: a node that sticks all period (or a contact point behind a spring that
sticks all period) holds its contact DOFs, so the modes of the structure with that part of the
interface held are linear (stable when the structure is damped) and ``T(s)`` does not see them;
its tangential position is the member of a family of stuck states that the stick anchors
select (docs/theory.md, "Full stick"), a neutral direction with multiplier exactly 1 that
:attr:`FloquetResult.neutral` counts.

Cost: one dense eigenvalue problem of ``2 (m' + q) H`` unknowns (``m'`` contact points with
mass, ``q`` other coordinates; at most :data:`PENCIL_MAX` before the companion form; less
where coordinates whose law does not vary over the period split off, harmonic by harmonic,
:func:`_components`) and,
with a memory, a few evaluations of ``T(s)`` and ``m H`` LU factorisations per refined
exponent (3-5 from a neighbour's exponent, 4-9 from a candidate; in 2D ``G(s)`` is split
once per solution into its part free of ``s`` and one outer product per stick interval,
:mod:`fretwear.hb.memory_gain`, and a refinement from a neighbour's exponent is one compiled
call, :func:`_refine`); along a sweep, where the
candidates are tracked, a few LU factorisations of the blocks of the quadratic problem per
candidate instead of its dense eigensolve (each solved by the LU of the Schur complement
on the unknowns that couple harmonics, the others eliminated harmonic by harmonic:
:mod:`fretwear.hb.hill_tracking`, whose compiled LU takes one ``abs`` an entry in its pivot
search: 27 -> 23 us at 31 unknowns; after a step within 1e-4 of the eigenvalue the next ones
on that step's LU, Neumaier's residual inverse iteration, two solves each, until the pair's
backward error is at rounding, :func:`_kept_step`: 16.3 -> 12.2 LUs a tracked point of the
two-DOF sweep, its tracking 0.93-0.94 of the CPU of the steps on a kept LU from 1e-7).
``det J`` is read from the solve's ``G`` (made again from the split of
:mod:`fretwear.hb.memory_gain` where it applies: equal to rounding) and ``Z~``
(:meth:`HillProblem.jacobian`). Where every node's normal coordinate is decoupled (a
prescribed normal force on a coordinate of its own), a refinement's evaluation forms and
factors only the tangential block of ``T(s)`` (:func:`_evaluate`, :func:`_hill_rows`; the
dropped block's column sums, the same at every ``s``, taken once a solution). Measured on
the benchmark's small models (docs/studies/method-costs.md, "Hill's method"): about
0.75-0.85 times the CPU a sweep spends on the point (median over both sweeps, load 2; the
Jenkins oscillator's points 0.37-0.54, about 0.4-0.5 ms against a solve of 0.8-1.4 ms, the
two-DOF oscillator's 1.0-1.5, a tracked one there about 1.5-2.5 ms), along a sweep, which
hands each point's own problem
(:func:`fretwear.hb.sweep_stability.point_problem`; :func:`stability` rebuilds it from the
solution, about 1.1-1.5 ms more there); the evaluations of ``T(s)`` (a law with a memory),
the inverse iterations of the tracked candidates and the dense eigensolve at the points that
cannot be tracked (a jump, a pair landing on the period-doubling line) are what cost. Dense
up to
:data:`DENSE_MAX` unknowns of the balance. The sign of ``det J`` (``J = T(0)``) is reported
with the exponents (:attr:`FloquetResult.det_sign`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from numba import njit
from scipy.linalg.lapack import dgecon, dgetrf, dgetrs, zgetrf, zgetrs
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components

from fretwear.errors import InputError
from fretwear.hb import contact as law
from fretwear.hb.contact import SEPARATION, STICK, _slip_gain
from fretwear.hb.dynamics import StructureDynamics, structure_dynamics
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.hill_tracking import (
    SPLIT_MAX_SHARE,
    _demote,
    _lu_into,
    _lu_small,
    _lu_solve_into,
    _lu_solve_small,
    _split_factor,
    _split_solve,
    no_split,
    shift_block,
    split_of,
    split_work,
)
from fretwear.hb.memory_gain import _gain_at, memory_gain
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.reduce import condense
from fretwear.hb.solution import PeriodicSolution
from fretwear.model.core import Model
from fretwear.resources import require_memory

#: Hill's matrix is formed and its quadratic eigenvalue problem solved densely up to this
#: many unknowns ``m H`` (the companion pencil has twice as many)
DENSE_MAX = 1500
#: the candidates' quadratic problem on the structure's coordinates is solved densely up to
#: this many unknowns ``(m + q) H`` (its companion form has twice as many; beyond, a dense
#: eigensolve takes minutes)
PENCIL_MAX = 1500
#: from this many unknowns ``(m + q) H`` of the candidates' quadratic problem on, its interior
#: coordinates are truncated to the modes of the structure with its contact points held below
#: :data:`HELD_CUTOFF` (:func:`truncated_structure`; below, the dense eigensolve is cheap: the
#: two-DOF oscillator's 155 unknowns take 3 ms)
TRUNCATE_FROM = 240
#: the held structure's modes kept for the candidates: circular frequency at most this times
#: the magnitude cut ``2 (k + 1) + 10`` (in units of ``w``) of the exponents reported; the
#: modes above would only give exponents beyond the cut, and their omission moves the kept
#: candidates by about ``(w_candidate / w_dropped)^2`` of their coupling (measured on the
#: virtual beam: docs/studies/method-costs.md, "Hill's method on a beam")
HELD_CUTOFF = 2.0
#: an exponent within this of Im s = +-w/2 (in units of w) is a real negative multiplier: its
#: conjugate is the other member of its family (the truncated problem puts the two a little
#: off the line: 1e-4 and 2.1e-3 measured on two two-DOF oscillators near period doubling)
EDGE_TOL = 1e-2
#: a member of a period-doubling family whose centroid the truncation puts up to this above
#: 1/2, within this of Im s = w/2, is kept when no other member is (:func:`_edge_members`)
EDGE_KAPPA = 0.05
#: margin on the thresholds of the centroid rule when a tracked member's neighbouring copy is
#: checked (:func:`_may_keep`): the centroids of one eigenvector found by inverse iteration
#: and by the dense eigensolver differ by rounding (about 1e-12 on the benchmark's models)
KAPPA_MARGIN = 1e-6
#: entries of the quadratic problem below this times the largest of their matrix are taken as
#: zeros when it is split into the blocks it decouples into (:func:`_components`): rounding of
#: the law's time-invariant parts (``P Q = I`` to 1e-16), whose dropping moves the exponents
#: by about as much
DECOUPLED_TOL = 1e-13
#: decoupled blocks of the quadratic problem are gathered up to at least this many unknowns
#: per dense eigensolve (below, the call's overhead exceeds the flops saved)
MIN_BLOCK = 48
#: a neighbouring copy whose start (the member's eigenvector moved by one harmonic) has a
#: backward error below this is taken as it is, without its inverse iteration
#: (:func:`_copy`: rounding; the blocks whose laws do not vary over the period give
#: 2e-17 to 4e-17 on the two-DOF oscillator, the truncated copies 1e-4 to 1e-3)
COPY_EXACT = 1e-15
#: exponents whose multiplier is below this are not refined (they decay within a period; the
#: factor e^{-s h} of the law's memory would overflow over a period)
NEGLIGIBLE = 1e-8
#: its logarithm (the floor of ``2 pi Re sigma``)
LOG_NEGLIGIBLE = float(np.log(NEGLIGIBLE))


@dataclass(frozen=True)
class HillOptions:
    """Settings of :func:`hill_stability`.

    refine : when the law has a memory, the candidates are refined on the exact ``T(s)`` in
        decreasing order of their real parts until this many have converged (each with its
        conjugate; the rest stay candidates; 0: none refined). A law without memory on a
        truncated pencil (:func:`truncated_structure`) has every candidate refined.
    step : step of the forward difference of ``T`` in ``s / w`` (Newton's derivative).
    newton_tol : relative residual ``|T v| / (|T| |v|)`` at which a refinement stops.
    newton_max_iter : iterations of one refinement.
    stable_tol : ``|rho| <= 1 + stable_tol`` counts as stable (rounding of a neutral exponent).
    track : given the result at a neighbouring solution (``previous`` of
        :func:`hill_stability`), continue its candidates by inverse iteration instead of the
        dense eigensolve, where that is shown to give the same ones (:func:`track_eigen`),
        and start each refinement from the neighbour's refined exponent of the same
        candidate (:func:`_warm_start`); False: the dense eigensolve and the refinements
        from the candidates at every point.
    """

    refine: int = 2
    step: float = 1e-6
    newton_tol: float = 1e-10
    newton_max_iter: int = 20
    stable_tol: float = 1e-6
    track: bool = True

    def __post_init__(self):
        if not isinstance(self.track, bool):
            raise InputError(f"track = {self.track!r}: expected true or false")
        n = self.refine
        if isinstance(n, bool) or not isinstance(n, int) or n < 0:
            raise InputError(f"refine = {n!r}: expected a whole number >= 0")
        for name in ("step", "newton_tol", "stable_tol"):
            v = getattr(self, name)
            if not (isinstance(v, int | float) and math.isfinite(v) and 0 < v < 1):
                raise InputError(f"{name} = {v!r}: expected a number between 0 and 1")
        n = self.newton_max_iter
        if isinstance(n, bool) or not isinstance(n, int) or n < 1:
            raise InputError(f"newton_max_iter = {n!r}: expected a whole number >= 1")


#: the settings :func:`hill_stability` takes without ``options`` (frozen: shared)
_DEFAULT_OPTIONS = HillOptions()


@dataclass
class HillTrack:
    """The centred candidates of one solution, for its neighbour (:func:`track_eigen`).

    sigma : (k,) the members ``s / w`` with ``Im s >= 0``; Y : (nd, k) their eigenvectors on
    the dynamic coordinates ``dyn``; block : (k,) the block of :class:`QuadraticReduction`
    each lies in; nd, dyn, blocks : that reduction's coordinates and blocks; complete : every
    family of the truncated problem is represented; refined : (k,) per member, its
    refinement on the exact ``T(s)`` as :class:`Refined` (None: not refined, or it did not
    converge); regime : the contact regime it was found in (:meth:`HillProblem.regime`);
    omega : the solution's circular frequency [rad/s]; velocity : (k,) per member, its motion
    ``d sigma / d omega`` [s/rad] from the neighbour it was continued from (0 where it was
    not, None for a dense eigensolve's): the next point's start moves it by as much
    (:func:`track_eigen`; the start only, the checks are the same).
    """

    sigma: np.ndarray
    Y: np.ndarray
    block: np.ndarray
    nd: int
    dyn: np.ndarray
    blocks: list
    complete: bool
    refined: list | None = None
    regime: tuple | None = None
    omega: float | None = None
    velocity: np.ndarray | None = None


@dataclass
class Refined:
    """The refinement of one candidate (:func:`_track`), for the neighbouring solution's
    (:func:`_warm_start`): ``sigma`` the exponent ``s / w`` of the exact ``T(s)`` continued
    from the candidate ``candidate`` (both in units of ``w``), ``v`` (m H,) its eigenvector,
    ``slope`` the last secant slope ``d mu / d sigma`` of the eigenvalue of ``T`` that vanishes
    there."""

    candidate: complex
    sigma: complex
    v: np.ndarray
    slope: complex


@dataclass
class FloquetResult:
    """Floquet exponents of a periodic solution by Hill's method (:func:`hill_stability`).

    Attributes
    ----------
    exponents : (k,) complex Floquet exponents ``s`` [1/s], sorted by decreasing real part:
        the member of each family ``s + i j w`` whose eigenvector is centred on the kept
        harmonics (the one continued from the time-invariant problem).
    multipliers : (k,) complex ``e^{s T}`` [-].
    centroid : (k,) harmonic centroid of each eigenvector [-] (:func:`centroid`).
    residual : (k,) relative residual ``|T(s) v| / (|T(s)| |v|)`` (NaN unless refined).
    kind : (k,) ``"exact"`` (the law has no memory at this solution and the quadratic
        problem is on the whole structure: it is exact), ``"refined"`` (refined on the exact
        ``T(s)``), ``"held"`` (a mode in which the contact points do not move: exact, not
        coupled to the law) or ``"candidate"`` (an eigenvalue of the quadratic problem, with
        the memory frozen or on a truncated interior, that was not refined: its multiplier is
        below :data:`NEGLIGIBLE`, or ``options.refine`` exponents with larger real parts were
        refined before it, or, for a law without memory, its refinement did not converge:
        the truncation of the interior moved it, it is no frozen-memory artefact).
    spurious : candidates of the frozen-memory problem near which the exact ``T(s)`` has no
        exponent (their refinement did not converge) [1/s]: not exponents, listed for
        inspection.
    neutral : tangential directions of nodes that stick all period: multipliers exactly 1
        (a family of stuck states; the anchors select the member), not in ``exponents``.
    omega : circular frequency of the solution [rad/s].
    evaluations : evaluations of ``T(s)``; wall_time : seconds.
    det_sign : sign of ``det J``, ``J = T(0)`` the balance's Jacobian (a change between
        neighbours of a branch: a fold or a branch point, :mod:`fretwear.hb.sweep_stability`).
    tracked : the candidates were continued from a neighbouring solution's
        (:func:`track_eigen`), not from a dense eigensolve.
    track : what a neighbouring solution continues from (None: it cannot).
    """

    exponents: np.ndarray
    multipliers: np.ndarray
    centroid: np.ndarray
    residual: np.ndarray
    kind: np.ndarray
    neutral: int
    omega: float
    spurious: np.ndarray
    evaluations: int
    wall_time: float
    stable_tol: float = 1e-6
    det_sign: int = 0
    tracked: bool = False
    track: HillTrack | None = None

    @property
    def period(self) -> float:
        return 2.0 * np.pi / self.omega

    @property
    def max_multiplier(self) -> float:
        """Largest ``|rho|`` [-] (0 when no exponent was found)."""
        return float(np.max(np.abs(self.multipliers), initial=0.0))

    @property
    def stable(self) -> bool:
        """Every multiplier inside the unit circle (to ``stable_tol``)."""
        return self.max_multiplier <= 1.0 + self.stable_tol

    @property
    def reliable(self) -> bool:
        """Every exponent was refined or is exact, and every eigenvector is centred on the kept
        harmonics (``|kappa| <= 1/2``): no candidate was left unrefined."""
        return not bool(np.any((self.kind == "candidate")
                               & (np.abs(self.multipliers) > NEGLIGIBLE))
                        or np.any(np.abs(self.centroid) > 0.5 + EDGE_TOL))

    def in_strip(self) -> np.ndarray:
        """The exponents shifted by multiples of ``i w`` into ``-w/2 < Im s <= w/2`` (the
        other usual representative; the same multipliers)."""
        w = self.omega
        shift = np.round(self.exponents.imag / w)
        return self.exponents - 1j * w * shift

    def critical(self, count: int = 2) -> np.ndarray:
        """The ``count`` multipliers of largest modulus."""
        order = np.argsort(-np.abs(self.multipliers), kind="stable")
        return self.multipliers[order[:count]]


# --------------------------------------------------------------------------------------------
# the law's derivative with the Floquet factor
# --------------------------------------------------------------------------------------------
@njit(cache=True)
def _shifted_gain(lam_u, lam_x, state, mu, P, Q, z, normal):
    """``G(s) = d lambda_x~ / d lambda_u~`` (nc, dH, dH) complex for the Floquet-periodic part
    of a perturbation ``e^{s t}``: the recursion of :func:`fretwear.hb.contact._dlft_jacobian`
    with every carried derivative multiplied by ``z = e^{-s h}`` (one sample step ``h``), the
    wrap-around solved for the periodic part. A singular wrap-around (a node that sticks all
    period at ``z^N = 1``) takes the least-squares seed: zero, as the anchors give."""
    nc, d, N = lam_u.shape
    H = P.shape[0]
    dt = d - 1
    dH = d * H
    G = np.zeros((nc, dH, dH), dtype=np.complex128)
    A0 = np.zeros((d, dH), dtype=np.complex128)
    S = np.zeros((d, dt), dtype=np.complex128)
    # the samples' rows, real and imaginary parts apart: P is real, so P times each is
    # half the flops of a complex product, a quarter of the complex P's
    Are = np.empty((d, N, dH))
    Aim = np.empty((d, N, dH))
    Sre = np.empty((d, N, dt))
    Sim = np.empty((d, N, dt))
    tmpA = np.zeros((dt, dH), dtype=np.complex128)
    tmpS = np.zeros((dt, dt), dtype=np.complex128)
    that = np.zeros(dt)
    B = np.zeros((dt, dt))
    Pr = np.ascontiguousarray(P)
    for p in range(nc):
        A0[:, :] = 0.0
        S[:, :] = 0.0
        for c in range(dt):
            S[1 + c, c] = 1.0
        fixed = not np.isnan(normal[p, 0])
        dcap = 0.0 if fixed else mu[p]
        for n in range(N):
            st = state[p, n]
            if st == SEPARATION:
                A0[:, :] = 0.0
                for c in range(d):
                    for h in range(H):
                        A0[c, c * H + h] = Q[n, h]
                S[:, :] = 0.0
            elif st == STICK:
                for c in range(dt):
                    for j in range(dH):
                        A0[1 + c, j] *= z
                    for j in range(dt):
                        S[1 + c, j] *= z
                A0[0, :] = 0.0
                S[0, :] = 0.0
                if fixed:
                    for h in range(H):
                        A0[0, h] = Q[n, h]
            else:  # slip: as contact.slip_derivative_step, the carried part times z
                m = n - 1 if n > 0 else N - 1
                pn = normal[p, n] if fixed else lam_u[p, 0, n]
                _slip_gain(lam_u[p], lam_x[p], n, lam_x[p, 1:, m], mu[p], pn, that, B)
                for a in range(dt):
                    for j in range(dH):
                        acc = 0.0 + 0.0j
                        for b in range(dt):
                            acc += B[a, b] * A0[1 + b, j]
                        tmpA[a, j] = z * acc
                    for j in range(dt):
                        acc = 0.0 + 0.0j
                        for b in range(dt):
                            acc += B[a, b] * S[1 + b, j]
                        tmpS[a, j] = z * acc
                for a in range(dt):
                    for j in range(dH):
                        A0[1 + a, j] = tmpA[a, j]
                    for h in range(H):
                        qh = Q[n, h]
                        for b in range(dt):
                            A0[1 + a, (1 + b) * H + h] += ((1.0 if a == b else 0.0)
                                                           - B[a, b]) * qh
                        A0[1 + a, h] += -dcap * that[a] * qh
                    for j in range(dt):
                        S[1 + a, j] = tmpS[a, j]
                A0[0, :] = 0.0
                S[0, :] = 0.0
                if fixed:
                    for h in range(H):
                        A0[0, h] = Q[n, h]
            for c in range(d):
                for j in range(dH):
                    Are[c, n, j] = A0[c, j].real
                    Aim[c, n, j] = A0[c, j].imag
                for j in range(dt):
                    Sre[c, n, j] = S[c, j].real
                    Sim[c, n, j] = S[c, j].imag
        Gp = G[p]
        PS = np.zeros((dH, dt), dtype=np.complex128)
        for c in range(d):
            if c == 0 and fixed:  # a prescribed normal force: the normal row of every
                # sample is Q's (no memory, S's row zero), so P times it is P Q
                Gp[:H, :H] = np.dot(Pr, Q)
                continue
            Gp[c * H:(c + 1) * H, :] = np.dot(Pr, Are[c]) + 1j * np.dot(Pr, Aim[c])
            PS[c * H:(c + 1) * H, :] = np.dot(Pr, Sre[c]) + 1j * np.dot(Pr, Sim[c])
        Mw = np.eye(dt).astype(np.complex128)
        for a in range(dt):
            for b in range(dt):
                Mw[a, b] -= S[1 + a, b]
        rhs = A0[1:, :].copy()
        smin = np.linalg.svd(Mw)[1].min()
        if smin > 1e-8:
            seed = np.linalg.solve(Mw, rhs)
        else:
            seed = np.linalg.lstsq(Mw, rhs)[0]
        Gp += np.dot(PS, np.ascontiguousarray(seed))
    return G


def shifted_gain(lam_u, lam_x, state, mu, P, Q, z: complex, normal=None) -> np.ndarray:
    """``G(s)`` (nc, dH, dH) complex for ``z = e^{-s h}`` (module docstring); ``normal``
    the prescribed normal forces (nc, N) [N] (NaN rows: unilateral), as
    :func:`fretwear.hb.contact.dlft_jacobian` takes them."""
    return _shifted_gain(np.ascontiguousarray(lam_u, dtype=float),
                         np.ascontiguousarray(lam_x, dtype=float), state,
                         np.ascontiguousarray(mu, dtype=float), np.ascontiguousarray(P),
                         np.ascontiguousarray(Q), complex(z), law._normal(normal, lam_u))


# --------------------------------------------------------------------------------------------
# Hill's matrix
# --------------------------------------------------------------------------------------------
def hill_blocks(Z0: np.ndarray, Zp: np.ndarray, Zm: np.ndarray) -> np.ndarray:
    """``Z(s)`` (m H, m H) complex, DOF-major as :func:`fretwear.hb.reduce.to_real_blocks`,
    from ``Z_r(s)`` (m, m) on the static coefficient and ``Z_r(s + i n w)``,
    ``Z_r(s - i n w)`` (k, m, m) on the cosine/sine pairs of the kept harmonics: with
    ``a = (U+ + U-)/2``, ``b = i (U+ - U-)/2``, the block of harmonic ``n`` maps ``[a; b]`` by
    ``[[(Zp + Zm)/2, i (Zm - Zp)/2], [i (Zp - Zm)/2, (Zp + Zm)/2]]`` (the real blocks
    ``[[Zr, Zi], [-Zi, Zr]]`` when ``Zm`` is the conjugate of ``Zp``)."""
    k, r, c = Zp.shape
    H = 1 + 2 * k
    out = np.zeros((r, H, c, H), dtype=complex)
    view = out.transpose(1, 3, 0, 2)
    view[0, 0] = Z0
    ca = np.arange(1, k + 1)
    cb = ca + k
    half = 0.5 * (Zp + Zm)
    view[ca, ca] = half
    view[cb, cb] = half
    view[ca, cb] = 0.5j * (Zm - Zp)
    view[cb, ca] = 0.5j * (Zp - Zm)
    return out.reshape(r * H, c * H)


def jacobian_form(G: np.ndarray, Z: np.ndarray, eps: float) -> np.ndarray:
    """``eps I - G (eps I - Z)`` (n, n) for ``G`` (nc, dH, dH) block-diagonal per node and
    ``Z`` (n, n), as the balance forms its Jacobian (eq. 22-28)."""
    nc, dH, _ = G.shape
    n = Z.shape[0]
    T = np.matmul(G, Z.reshape(nc, dH, n)).reshape(n, n)
    for p in range(nc):
        sl = slice(p * dH, (p + 1) * dH)
        T[sl, sl] -= eps * G[p]
    T[np.diag_indices(n)] += eps
    return T


@njit(cache=True)
def _state_summary(state):
    """Per node of ``state`` (nc, N) (the law's samples' states, 0 separation, 1 stick, 2
    slip): ``present`` (nc, 3) the states it takes and ``changes`` (nc,) how many times it
    changes state over the period (the last sample to the first included), in one pass."""
    nc, N = state.shape
    present = np.zeros((nc, 3), dtype=np.bool_)
    changes = np.zeros(nc, dtype=np.int64)
    for p in range(nc):
        last = state[p, N - 1]
        for n in range(N):
            st = state[p, n]
            present[p, st] = True
            if st != last:
                changes[p] += 1
            last = st
    return present, changes


@njit(cache=True)
def _det_sign(G, Z, eps):
    """Sign of ``det(eps I - G (eps I - Z))`` (:func:`jacobian_form`, real; ``G`` (nc, dH,
    dH) block-diagonal per node, ``Z`` (n, n)): the form, then its LU with partial pivoting
    (the pivots' signs and the permutation's parity); 0 at a zero pivot. A zero of ``G``
    and a zero multiplier of the elimination add only zeros (``Z`` and ``J`` finite): they
    are skipped, the same numbers (where a normal block is decoupled, as a Jenkins
    oscillator's, ``J`` is block-diagonal and the elimination runs on its blocks)."""
    nc, dH, _ = G.shape
    n = Z.shape[0]
    J = np.zeros((n, n))
    for p in range(nc):
        lo = p * dH
        for i in range(dH):  # each entry's terms summed in r's order, the rows of Z read
            for r in range(dH):  # contiguously
                g = G[p, i, r]
                if g == 0.0:
                    continue
                for j in range(n):
                    J[lo + i, j] += g * Z[lo + r, j]
            for j in range(dH):
                J[lo + i, lo + j] -= eps * G[p, i, j]
    for i in range(n):
        J[i, i] += eps
    sign = 1
    for col in range(n):
        piv = col
        big = abs(J[col, col])
        for r in range(col + 1, n):
            if abs(J[r, col]) > big:
                piv, big = r, abs(J[r, col])
        if big == 0.0:
            return 0
        if piv != col:
            for j in range(n):
                J[col, j], J[piv, j] = J[piv, j], J[col, j]
            sign = -sign
        d = J[col, col]
        if d < 0.0:
            sign = -sign
        for r in range(col + 1, n):
            f = J[r, col] / d
            if f == 0.0:
                continue
            for j in range(col + 1, n):
                J[r, j] -= f * J[col, j]
    return sign


@njit(cache=True)
def _hill_matrix(G, Zr, eps):
    """``T(s) = eps I - G(s) (eps I - Z(s))`` (m H, m H) complex (:func:`jacobian_form` of
    :func:`hill_blocks`) from ``G(s)`` (nc, dH, dH) and ``Z_r`` (1 + 2k, m, m) at ``s``,
    ``s + i n w``, ``s - i n w`` (:meth:`HillProblem.stiffness`), in one compiled call: the
    product ``G Z`` over the nonzero entries of ``Z(s)`` only (per column, the harmonic's
    own coefficient and its cosine/sine partner of every DOF: ``2 m`` terms, not ``m H``),
    which at the sizes of a refinement (tens of unknowns) costs less than the calls of the
    numpy form. The same terms as the dense product, summed in another order: equal to a
    few units of rounding. :func:`_hill_rows` on every unknown."""
    n = Zr.shape[1] * Zr.shape[0]
    return _hill_rows(G, Zr, eps, np.arange(n), n)


@njit(cache=True)
def _hill_rows(G, Zr, eps, at, nk):
    """The rows and columns of :func:`_hill_matrix`'s ``T(s)`` that ``at`` (m H,) keeps:
    ``T[i, j]`` goes to ``[at[i], at[j]]`` of the (nk, nk) result, a negative ``at`` drops
    it; each kept entry computed as the whole matrix's (the same values), the dropped ones
    not at all (:func:`_evaluate`: the tangential block, a quarter of the entries)."""
    nl, m, _ = Zr.shape
    k = (nl - 1) // 2
    H = 1 + 2 * k
    n = m * H
    nc, dH, _ = G.shape
    T = np.zeros((nk, nk), dtype=np.complex128)
    some = np.zeros(m, dtype=np.bool_)  # a DOF with a column kept
    for c in range(m):
        for h in range(H):
            some[c] = some[c] or at[c * H + h] >= 0
    for p in range(nc):
        lo = p * dH
        for i in range(dH):
            row = at[lo + i]
            if row < 0:
                continue
            for c in range(m):
                if not some[c]:
                    continue
                acc = 0.0 + 0.0j
                for r in range(m):
                    acc += G[p, i, r * H - lo] * Zr[0, r, c] if lo <= r * H < lo + dH else 0.0
                if at[c * H] >= 0:
                    T[row, at[c * H]] = acc
                for j in range(k):
                    ia, ib = 1 + j, 1 + k + j
                    acc_a = 0.0 + 0.0j
                    acc_b = 0.0 + 0.0j
                    for r in range(m):
                        ca, cb = r * H + ia - lo, r * H + ib - lo
                        if not (0 <= ca < dH):
                            continue
                        zp = Zr[1 + j, r, c]
                        zm = Zr[1 + k + j, r, c]
                        half = 0.5 * (zp + zm)
                        ga, gb = G[p, i, ca], G[p, i, cb]
                        acc_a += ga * half + gb * (0.5j * (zp - zm))
                        acc_b += ga * (0.5j * (zm - zp)) + gb * half
                    if at[c * H + ia] >= 0:
                        T[row, at[c * H + ia]] = acc_a
                    if at[c * H + ib] >= 0:
                        T[row, at[c * H + ib]] = acc_b
        for i in range(dH):
            row = at[lo + i]
            if row < 0:
                continue
            for j in range(dH):
                if at[lo + j] >= 0:
                    T[row, at[lo + j]] -= eps * G[p, i, j]
    for i in range(n):
        if at[i] >= 0:
            T[at[i], at[i]] += eps
    return T


#: the most interior coordinates ``q`` for which :meth:`HillProblem.matrix` condenses in the
#: compiled, unblocked elimination of :func:`_condensed_at`; beyond, LAPACK's blocked solve
#: (:meth:`StructureDynamics.condensed`) is faster (one ``T(s)`` on FE blocks, one BLAS
#: thread: q = 20 0.4 ms compiled / 0.3 ms LAPACK, q = 88 8.1 / 3.7 ms, q = 336 267 / 58 ms,
#: the same values to 1e-15), while on the small oscillators (q <= 2) the compiled call is
#: 2-3 times faster
CONDENSED_COMPILED_MAX = 16


@njit(cache=True)
def _condensed_at(Kf, Mf, Cf, Df, m, harmonics, omega, sigma):
    """``(Z_r, ok)``: ``Z_r`` (1 + 2k, m, m) complex at ``lambda = s``, ``s + i n w``,
    ``s - i n w`` (``s = sigma w``), the hysteretic term signed by ``Im lambda``, from the
    structure's whole matrices (m + q, m + q) (``Cf``, ``Df`` zero where the model has none):
    the Schur complement ``Z^xx - Z^xq (Z^qq)^-1 Z^qx`` (:meth:`StructureDynamics.condensed`)
    by the LU of the ``q x q`` block (:func:`_lu_small`, :func:`_lu_solve_small`), in one
    compiled call (the same values to rounding); ``ok`` False where that block is singular."""
    k = harmonics.size
    ns = Kf.shape[0]
    q = ns - m
    s = sigma * omega
    Zr = np.empty((1 + 2 * k, m, m), dtype=np.complex128)
    Z = np.empty((ns, ns), dtype=np.complex128)
    A = np.empty((q, q), dtype=np.complex128)
    X = np.empty((q, m), dtype=np.complex128)
    x = np.empty(q, dtype=np.complex128)
    b = np.empty(q, dtype=np.complex128)
    piv = np.empty(q, dtype=np.int64)
    for idx in range(1 + 2 * k):
        if idx == 0:
            lam = s
        elif idx <= k:
            lam = s + 1j * (harmonics[idx - 1] * omega)
        else:
            lam = s - 1j * (harmonics[idx - 1 - k] * omega)
        a = lam * lam
        c = 1j * np.sign(lam.imag)
        for i in range(ns):
            for j in range(ns):
                Z[i, j] = ((a * Mf[i, j] + Kf[i, j]) + lam * Cf[i, j]) + c * Df[i, j]
        for i in range(q):
            for j in range(q):
                A[i, j] = Z[m + i, m + j]
            for j in range(m):
                X[i, j] = Z[m + i, j]
        # X = A^-1 X in place by :func:`_lu_into` and :func:`_lu_solve_into` on the arrays
        # made once (_lu_small and _lu_solve_small allocate: three arrays a value of lambda)
        if not _lu_into(A, piv):
            return Zr, False
        for j in range(m):
            for i in range(q):
                b[i] = X[i, j]
            _lu_solve_into(A, piv, b, x)
            for i in range(q):
                X[i, j] = x[i]
        for i in range(m):
            for j in range(m):
                acc = Z[i, j]
                for t in range(q):
                    acc -= Z[i, m + t] * X[t, j]
                Zr[idx, i, j] = acc
    return Zr, True


class HillProblem:
    """``T(s)`` of a converged solution ``U`` (m, H) of ``prob`` (module docstring), with the
    structure ``dyn`` for ``Z_r`` at complex arguments. Evaluated in ``sigma = s / w``."""

    def __init__(self, prob: DLFTProblem, U, dyn: StructureDynamics):
        if prob.reduced.quasi_static or not prob.reduced.omega > 0:
            raise InputError("stability of a quasi-static solution: there are no dynamics "
                             "(expected a solution at a frequency > 0)")
        n = prob.m * prob.H
        if n > DENSE_MAX:
            raise InputError(f"Hill's method forms {n} x {n} matrices densely up to "
                             f"{DENSE_MAX} unknowns (m H)")
        if dyn.m != prob.m:
            raise InputError(f"the structure has {dyn.m} contact DOFs, the problem {prob.m}")
        # T(s) and its factorisation and derivative (n x n complex, a few), the gains G
        # (nc blocks of d H), and the pencil's three real matrices on (m + q) H unknowns with
        # the companion eigenproblem (twice as many, complex, with its eigenvectors)
        npen = min((dyn.m + dyn.q) * prob.H, PENCIL_MAX)  # pencil() refuses beyond
        require_memory(16.0 * 6 * n * n + 16.0 * prob.nc * (prob.d * prob.H) ** 2
                       + 8.0 * 4 * npen**2 + 16.0 * 3 * (2 * npen) ** 2,
                       f"Hill's method on {n:,} unknowns ({prob.m:,} contact DOFs x {prob.H} "
                       f"Fourier coefficients, {dyn.q:,} interior coordinates)")
        self.prob = prob
        self.U = np.asarray(U, dtype=float).reshape(prob.m, prob.H)
        self.dyn = dyn
        self.omega = float(prob.reduced.omega)
        self.harmonics = np.asarray(prob.basis.harmonics, dtype=float)
        self.N = prob.basis.n_samples
        lu, lx, state, _ = prob.time_law(self.U)
        self.lu = np.ascontiguousarray(lu)
        self.lx = np.ascontiguousarray(lx)
        self.state = state
        # the law's arrays as the kernel of :func:`shifted_gain` takes them, made once
        self._law = (np.ascontiguousarray(prob.mu, dtype=float), np.ascontiguousarray(prob.P),
                     np.ascontiguousarray(prob.Q), prob.normal_samples)
        self._summary = None  # the contact states per node (:meth:`_states`)
        # in 2D, G(s) split once into its part free of s and one outer product per stick
        # interval (:mod:`fretwear.hb.memory_gain`; None: the recursion at every s), where
        # a node sticks (otherwise nothing is refined); G(0) from the split wherever it
        # applies, the solve's recursion elsewhere
        sticks = any(f[STICK] for f in self._states()[0])
        split = memory_gain(self.lu, self.lx, self.state, *self._law)
        self._memory = split if sticks else None
        if split is not None:  # G(0) from the split: the solve's recursion's terms summed
            # in another order (no node sticks all period, so the solve's wrap-around is
            # exact in one sweep and its anchors do not enter): equal to rounding; without a
            # stick interval the split is G(0) itself, made at 0.6 of the recursion's cost
            self.G0 = np.ascontiguousarray(split.at(1.0).real)
        else:
            self.G0 = law.dlft_jacobian(self.lu, self.lx, self.state, prob.mu, prob.P, prob.Q,
                                        prob.eps * prob.anchor, prob.tol, prob.max_sweeps,
                                        prob.normal)
        # the structure's whole matrices as :func:`_condensed_at` takes them (zeros for a
        # damping the model has not)
        full = dyn.full
        zero = np.zeros_like(full["K"])
        self._structure = tuple(full.get(nm, zero) for nm in ("K", "M", "C", "D"))
        # the split G(s) as :func:`_evaluate` takes it, where every piece of an evaluation
        # runs compiled (None: the pieces one by one, :meth:`matrix` and :func:`_pair`)
        mg = self._memory
        small = (dyn.q <= CONDENSED_COMPILED_MAX and n <= PAIR_COMPILED_MAX)
        self._fused = ((mg.constant, mg.node, mg.start, mg.length, mg.rows, mg.P)
                       if mg is not None and small else None)
        # the unknowns the compiled pair works on (:func:`_decoupled_normals`)
        self._keep = (_decoupled_normals(mg, self._structure, prob.H, float(prob.eps))
                      if self._fused is not None else None)
        self._dropped = -1.0  # the dropped columns' largest sum, once known (:func:`_evaluate`)
        self.evaluations = 0
        # the structure the candidates' pencil is formed on, and its interior coordinates'
        # count (:func:`truncated_structure`), made at the first :meth:`pencil`
        self._candidates: tuple | None = None

    @property
    def candidate_structure(self) -> tuple[tuple, int]:
        """``((K, M, C, D), q)``: the structure the candidates' pencil (:meth:`pencil`) is
        formed on and its number of interior coordinates: the structure itself, or its
        interior truncated to the held modes below the cutoff (:func:`truncated_structure`)."""
        if self._candidates is None:
            self._candidates = truncated_structure(self._structure, self.dyn, self.prob.H,
                                                   self.harmonics.size, self.omega)
        return self._candidates

    @property
    def truncated(self) -> bool:
        """The candidates' pencil is on a truncated interior (:attr:`candidate_structure`):
        its eigenvalues are candidates even where the law has no memory."""
        return self.candidate_structure[1] < self.dyn.q

    def gain(self, sigma: complex) -> np.ndarray:
        """``G(s)`` at ``s = sigma w`` (the solve's own ``G`` at 0)."""
        if sigma == 0:
            return self.G0.astype(complex)
        z = np.exp(-2.0 * np.pi * complex(sigma) / self.N)  # e^{-s h}: h = T / N
        if self._memory is not None:
            return self._memory.at(z)
        mu, P, Q, normal = self._law
        return _shifted_gain(self.lu, self.lx, self.state, mu, P, Q, z, normal)

    def condensed(self, sigma: complex) -> np.ndarray:
        """``Z_r`` (1 + 2k, m, m) at ``s``, ``s + i n w``, ``s - i n w`` for ``s = sigma w``,
        with the hysteretic damping signed by the frequency ``Im(s) + n w`` of each."""
        w = self.omega
        s = complex(sigma) * w
        nw = 1j * self.harmonics * w
        lam = np.concatenate([[s], s + nw, s - nw])
        return self.dyn.condensed(lam * lam, lam, 1j * np.sign(lam.imag))

    def stiffness(self, sigma: complex) -> np.ndarray:
        """``Z(s)`` (m H, m H) at ``s = sigma w``: ``Z_r(s + i n w)`` with the hysteretic
        damping signed by the frequency ``Im(s) + n w`` of each component."""
        k = self.harmonics.size
        Zr = self.condensed(sigma)
        return hill_blocks(Zr[0], Zr[1:k + 1], Zr[k + 1:])

    def matrix(self, sigma: complex) -> np.ndarray:
        """``T(s)`` (m H, m H) complex at ``s = sigma w``: ``jacobian_form(gain, stiffness)``
        with the product and the blocks in one compiled call (:func:`_hill_matrix`)."""
        self.evaluations += 1
        if self._structure[0].shape[0] - self.prob.m > CONDENSED_COMPILED_MAX:
            return _hill_matrix(self.gain(sigma), self.condensed(sigma), float(self.prob.eps))
        Zr, ok = _condensed_at(*self._structure, self.prob.m, self.harmonics, self.omega,
                               complex(sigma))
        if not ok:
            raise InputError("the structure with its contact points held is singular at a "
                             "value of the Laplace variable (an eigenvalue of the held "
                             "interface)")
        return _hill_matrix(self.gain(sigma), Zr, float(self.prob.eps))

    def evaluate(self, sigma: complex, v: np.ndarray, mu0: complex):
        """One step of the refinement (:func:`_track`) at ``s = sigma w``: ``T(s)``
        (:meth:`matrix`), the eigenpair ``(mu, y)`` of :func:`_pair` from ``v`` shifted by
        ``mu0``, and the residuals ``|mu| / |T|``, ``|T y - mu y| / |T|`` (1-norm of ``T``;
        compiled, :func:`_residuals`, where the pair ran compiled). Returns
        ``(T, mu, y, lu, res, pair)`` (``lu`` as :func:`_pair` returns it)."""
        if self._fused is not None:
            T, mu, y, status, res, pair = self._evaluate(sigma, v, mu0)
            if status == 0:
                return T, complex(mu), y, None, float(res), float(pair)
            mu, y, lu = _pair_lapack(T, v, mu0)  # a zero pivot: as :func:`_pair` does
        else:
            T = self.matrix(sigma)
            mu, y, lu = _pair(T, v, mu0)
        if lu is None:
            res, pair = _residuals(T, y, complex(mu), 0.0)
            return T, mu, y, None, float(res), float(pair)
        scale = np.linalg.norm(T, 1)
        pair = float(np.linalg.norm(T @ y - mu * y) / scale)
        return T, mu, y, lu, max(float(abs(mu) / scale), pair), pair

    def _evaluate(self, sigma: complex, v: np.ndarray, mu0: complex):
        """The compiled evaluation (:func:`_evaluate`): ``(T, mu, y, status, res, pair)``;
        raises where the held structure is singular (as :meth:`matrix`)."""
        self.evaluations += 1
        sigma = complex(sigma)
        z = (1.0 + 0j if sigma == 0 else np.exp(-2.0 * np.pi * sigma / self.N))
        out = _evaluate(*self._fused, complex(z), *self._structure, self.prob.m,
                        self.harmonics, self.omega, sigma, float(self.prob.eps),
                        np.ascontiguousarray(v, dtype=complex), complex(mu0), 2, self._keep,
                        self._dropped, True)
        if out[3] == 2:
            raise InputError("the structure with its contact points held is singular at a "
                             "value of the Laplace variable (an eigenvalue of the held "
                             "interface)")
        self._dropped = out[6]
        return out[:6]

    def jacobian(self) -> np.ndarray:
        """``J = T(0)`` (m H, m H) real: the balance's Jacobian from the solve's own ``G``
        and its problem's ``Z~`` (eq. 22-28), not re-assembled from the structure (the same
        matrix to rounding, tests/hb/test_stability.py)."""
        return jacobian_form(self.G0, self.prob.Z, self.prob.eps)

    def det_sign(self) -> int:
        """Sign of ``det J`` (:meth:`jacobian`), from its LU with partial pivoting: in one
        compiled call up to :data:`PAIR_COMPILED_MAX` unknowns (:func:`_det_sign`;
        ``np.linalg.slogdet``'s sign to rounding: the same pivots), LAPACK's beyond."""
        if self.prob.m * self.prob.H > PAIR_COMPILED_MAX:
            return int(np.sign(np.linalg.slogdet(self.jacobian())[0]))
        return int(_det_sign(self.G0, np.ascontiguousarray(self.prob.Z, dtype=float),
                             float(self.prob.eps)))

    def _states(self):
        """``(present, changes)`` of :func:`_state_summary` as lists (per node, the three
        flags and the count: the nodes are few, and the questions below are cheaper on
        Python's scalars than on arrays), made at the first call (the state does not
        change)."""
        if self._summary is None:
            present, changes = _state_summary(np.ascontiguousarray(self.state))
            self._summary = (present.tolist(), changes.tolist())
        return self._summary

    def neutral(self) -> int:
        """Tangential directions of the nodes that stick all period (multiplier 1)."""
        present, _ = self._states()
        stuck = sum(1 for f in present if f[STICK] and not f[SEPARATION] and not f[law.SLIP])
        return stuck * (self.prob.d - 1)

    def regime(self) -> tuple:
        """Per node, the contact states it takes over the period and how many times it
        changes state: where a neighbouring solution's differ (a node that begins to slip or
        to separate, a stick interval born or closed), the law's derivative ``G`` changes its
        structure and the frozen-memory problem's families with it (a held pair goes, real
        exponents come: measured on a Jenkins oscillator leaving full stick), so the
        candidates are not continued from the neighbour's (:func:`hill_stability`)."""
        present, changes = self._states()
        return tuple((tuple(k for k in range(3) if f[k]), c)
                     for f, c in zip(present, changes, strict=True))

    def memoryless(self) -> bool:
        """No node sticks at any instant nor slips in 3D: ``G(s) = G(0)`` for every ``s``
        (separation and 2D slip carry nothing from the previous instant)."""
        present, _ = self._states()
        return not any(f[STICK] or (self.prob.d > 2 and f[law.SLIP]) for f in present)

    def pencil(self):
        """``(A0, A1, A2)``: Hill's matrix on the structure's coordinates ``(x, q)`` (every
        coordinate with the kept harmonics, ``(m + q) H`` unknowns), a quadratic polynomial
        ``A0 + sigma A1 + sigma^2 A2`` in ``sigma = s / w`` when the law's memory is frozen
        (``G(s) = G(0)``): rows of ``x``: ``eps x - G (eps x - Z^xx x - Z^xq q)``, rows of
        ``q``: ``Z^qx x + Z^qq q``, with ``Z^ab(lambda)`` of ``lambda = w (sigma + i n)``.
        Exact for a law without memory (:meth:`memoryless`) on the whole structure; the
        hysteretic damping keeps the sign of ``n`` (none on the static coefficient). Formed
        on :attr:`candidate_structure`: on a large problem (:data:`TRUNCATE_FROM`) ``q`` the
        held structure's modes below the cutoff only. Compiled (:func:`_pencil`)."""
        dyn, prob, w = self.dyn, self.prob, self.omega
        (K, M, C, D), q = self.candidate_structure
        if (dyn.m + q) * prob.H > PENCIL_MAX:
            raise InputError(f"Hill's method solves its quadratic eigenvalue problem densely "
                             f"up to {PENCIL_MAX} unknowns (structure coordinates x kept "
                             f"harmonics); this one has {(dyn.m + q) * prob.H}: use fewer "
                             "harmonics or a modal condenser with fewer modes")
        nw = np.ascontiguousarray(prob.basis.orders * w, dtype=float)
        A = _pencil(K, M, C, D, np.ascontiguousarray(self.G0, dtype=float),
                    float(prob.eps), nw, w)
        return A[0], A[1], A[2]


def truncated_structure(structure: tuple, dyn: StructureDynamics, H: int, k: int,
                        omega: float) -> tuple[tuple, int]:
    """``((K, M, C, D), r)``: the structure's whole matrices (``structure``, on ``(x, q)``)
    with the interior ``q`` truncated for the candidates' pencil to ``r`` coordinates: the
    held structure's modes (:attr:`~fretwear.hb.dynamics.StructureDynamics.held_modes`,
    mass-normalised) of circular frequency at most :data:`HELD_CUTOFF` times the magnitude
    cut ``2 (k + 1) + 10`` times ``omega`` (``k`` kept harmonics), and the interior's static
    response to the contact coordinates, ``Psi = -(K^qq)^-1 K^qx`` (zero where ``q`` is
    already the motion relative to the static shape, :mod:`fretwear.hb.dynamics`; not where
    contact springs put the structure's DOFs in ``q``): ``[x; q] = [[I, 0], [Psi, Phi_r]]
    [x; eta]`` (Craig and Bampton's transformation, AIAA J. 6, 1968), each matrix ``T^T X T``
    (a Galerkin projection: the statics exact, the couplings and the damping projected as
    they are).

    Why it serves: the family of a mode far from the contact's influence sits near
    ``i w_j``, so the modes above the cutoff only give exponents beyond the cut, which are not
    reported; what their omission changes in the kept candidates (the dynamic part of their
    coupling, of the order of ``(s / w_j)^2``: 1e-4 relative on the beam of
    tests/hb/test_stability_truncated.py) the refinement on the exact ``T(s)`` removes: every
    candidate of a truncated pencil is refined or reported as a candidate
    (:func:`hill_stability`). Without ``Psi`` the same beam's candidates were 5-14 % off and
    their refinements failed.

    The structure as it is (``r = q``) below :data:`TRUNCATE_FROM` unknowns ``(m + q) H``,
    on a modal condenser's interior (``dyn.exact`` False: its fixed-interface modes and
    residual vectors; on the shipped dovetail's, 16 of 262 kept, a refined exponent of
    ``|rho|`` 2.56 came out at a point that the whole pencil of a condensation without
    residual vectors finds stable, docs/studies/dovetail-fold-stability.md: not truncated
    until that is understood), without a modal basis of the interior (a massless interior
    coordinate), with a singular ``K^qq``, or where every mode is kept."""
    m, q = dyn.m, dyn.q
    if q == 0 or (m + q) * H < TRUNCATE_FROM or not dyn.exact:
        return structure, q
    modes = dyn.held_modes
    if modes is None:
        return structure, q
    w2, Phi = modes
    keep = w2 <= (HELD_CUTOFF * (2.0 * (k + 1) + 10.0) * omega) ** 2
    r = int(np.count_nonzero(keep))
    if r == q:
        return structure, q
    K = structure[0]
    try:  # the static response of the interior to each contact coordinate
        Psi = -np.linalg.solve(K[m:, m:], K[m:, :m])
    except np.linalg.LinAlgError:
        return structure, q
    T = np.zeros((m + q, m + r))
    T[:m, :m] = np.eye(m)
    T[m:, :m] = Psi
    T[m:, m:] = Phi[:, keep]
    return tuple(np.ascontiguousarray(T.T @ X @ T) for X in structure), r


@njit(cache=True)
def _pencil(K, M, C, D, G, eps, nw, w):
    """:meth:`HillProblem.pencil` compiled: ``A`` (3, n, n), ``n = r H`` in the DOF-major
    layout of :func:`fretwear.hb.reduce.to_real_blocks`, from the structure's whole matrices
    (r, r) and the law's ``G`` (nc, dH, dH) of the first ``nc d`` coordinates. The complex
    blocks of ``Z`` per harmonic ``h`` (``nw[h]`` its circular frequency, ``nw[0] = 0``) and
    power of ``sigma``: ``K - nw^2 M + i (nw C + D)`` (no ``D`` on the static coefficient),
    ``w C + 2 i w nw M``, ``w^2 M``; each couples only the cosine and sine coefficients of
    its own harmonic, so the rows of ``x`` (``G Z``) sum ``2 d`` terms an entry, not ``dH``.
    Equal to the numpy form (``np.block``-free products of numpy's) to rounding."""
    r = K.shape[0]
    nb = nw.size
    k = nb - 1
    H = 1 + 2 * k
    n = r * H
    nc, dH = G.shape[0], G.shape[1]
    d = dH // H
    nx = nc * dH
    m = nc * d
    A = np.zeros((3, n, n))  # rows of q: Z itself
    Z = np.zeros((3, nx, n))  # rows of x: Z, multiplied by G below
    for h in range(nb):
        for j in range(r):
            X = Z if j < m else A  # the same row index in either
            for col in range(r):
                re0 = K[j, col] - nw[h] * nw[h] * M[j, col]
                im0 = nw[h] * C[j, col] + (D[j, col] if h > 0 else 0.0)
                re1 = w * C[j, col]
                im1 = 2.0 * w * nw[h] * M[j, col]
                re2 = w * w * M[j, col]
                if h == 0:
                    X[0, j * H, col * H] = re0
                    X[1, j * H, col * H] = re1
                    X[2, j * H, col * H] = re2
                    continue
                a, b = j * H + h, j * H + h + k
                ca, cb = col * H + h, col * H + h + k
                X[0, a, ca], X[0, a, cb], X[0, b, ca], X[0, b, cb] = re0, im0, -im0, re0
                X[1, a, ca], X[1, a, cb], X[1, b, ca], X[1, b, cb] = re1, im1, -im1, re1
                X[2, a, ca], X[2, b, cb] = re2, re2
    lo = np.empty(n, dtype=np.int64)  # per column, its coefficient's harmonic pair
    hi = np.empty(n, dtype=np.int64)
    for col in range(n):
        c = col % H
        if c == 0:
            lo[col], hi[col] = 0, 0
        elif c <= k:
            lo[col], hi[col] = c, c + k
        else:
            lo[col], hi[col] = c - k, c
    zl = np.zeros((d, n))  # per column, the two entries of Z's rows of x it meets (gathered
    zh = np.zeros((d, n))  # once: the rows' scattered reads cost most of the product)
    for pw in range(3):
        for p in range(nc):
            cols = np.zeros(n, dtype=np.int64)  # the columns these rows meet (the others'
            nz = 0  # products are zeros: A keeps its)
            for col in range(n):
                hit = False
                for jj in range(d):
                    base = (p * d + jj) * H
                    zl[jj, col] = Z[pw, base + lo[col], col]
                    zh[jj, col] = Z[pw, base + hi[col], col]
                    hit = hit or zl[jj, col] != 0 or zh[jj, col] != 0
                if hit:
                    cols[nz] = col
                    nz += 1
            for i in range(dH):
                row = p * dH + i
                for t in range(nz):
                    col = cols[t]
                    a, b = lo[col], hi[col]
                    acc = 0.0
                    for jj in range(d):
                        acc += G[p, i, jj * H + a] * zl[jj, col]
                        if b != a:
                            acc += G[p, i, jj * H + b] * zh[jj, col]
                    A[pw, row, col] = acc
    for p in range(nc):
        for i in range(dH):
            for t in range(dH):
                A[0, p * dH + i, p * dH + t] -= eps * G[p, i, t]
    for i in range(nx):
        A[0, i, i] += eps
    return A


def centroid(p: np.ndarray, k: int) -> np.ndarray:
    """Harmonic centroid of Hill eigenvectors ``p`` (..., r, 1 + 2k) complex,
    real-coefficient layout ``[a0, a.., b..]``: ``sum_n n |c_n|^2 / sum |c_n|^2`` over their
    complex-exponential coefficients ``c_{+n} = (a_n - i b_n)/2``,
    ``c_{-n} = (a_n + i b_n)/2``, ``c_0 = a0``; harmonic orders are taken as their index
    among the kept harmonics (``1..k``). A float for one vector, an array (...) otherwise.
    Compiled (:func:`_centroids`: a call of numpy's dozen operations cost 15-20 us on a
    single vector, and a tracked point computes one per inverse iteration)."""
    p = np.asarray(p)
    lead = p.shape[:-2]
    flat = np.ascontiguousarray(p.reshape((-1,) + p.shape[-2:]), dtype=complex)
    out = _centroids(flat, int(k)).reshape(lead)
    return float(out) if np.ndim(out) == 0 else out


@njit(cache=True)
def _centroids(p, k):
    """:func:`centroid` of the vectors ``p`` (B, r, 1 + 2k) complex: (B,)."""
    nv, r = p.shape[0], p.shape[1]
    out = np.empty(nv)
    for v in range(nv):
        total = 0.0
        moment = 0.0
        for i in range(r):
            total += p[v, i, 0].real ** 2 + p[v, i, 0].imag ** 2
            for n in range(k):
                a, b = p[v, i, 1 + n], p[v, i, 1 + k + n]
                cp = a - 1j * b  # 2 c_{+n}, 2 c_{-n}
                cm = a + 1j * b
                wp = (cp.real ** 2 + cp.imag ** 2) / 4.0
                wm = (cm.real ** 2 + cm.imag ** 2) / 4.0
                total += wp + wm
                moment += (n + 1) * (wp - wm)
        out[v] = moment / max(total, 1e-300)
    return out


@dataclass
class QuadraticReduction:
    """``A0 + s A1 + s^2 A2`` with its algebraic coordinates eliminated
    (:func:`reduce_quadratic`): ``B0 + s B1 + s^2 B2`` on the coordinates ``dyn`` with a mass
    or a damping, the algebraic ones ``alg = back @ y[dyn]``; ``blocks`` the index sets (into
    ``dyn``) of the blocks the problem decouples into (:func:`_components`)."""

    n: int
    dyn: np.ndarray
    alg: np.ndarray
    back: np.ndarray | None
    B0: np.ndarray
    B1: np.ndarray
    B2: np.ndarray
    blocks: list

    def full(self, Y: np.ndarray) -> np.ndarray:
        """Eigenvectors (n, k) on every coordinate from those (nd, k) on ``dyn``."""
        vecs = np.zeros((self.n, Y.shape[1]), dtype=complex)
        vecs[self.dyn] = Y
        if self.alg.size:
            vecs[self.alg] = self.back @ Y
        return vecs


def reduce_quadratic(A0: np.ndarray, A1: np.ndarray, A2: np.ndarray,
                     hint: HillTrack | None = None) -> QuadraticReduction:
    """Coordinates whose rows and columns of ``A1`` and ``A2`` vanish (massless contact points
    behind springs, rows the law holds) are algebraic: eliminated exactly by the Schur
    complement of ``A0`` (their blocks do not depend on ``s``); the rest split into the blocks
    it decouples into (:func:`_components`; ``hint``: a neighbour's, kept when the problem
    decouples into them by the same test, which costs less than finding them). Where the
    algebraic block of ``A0`` is diagonal (the contact points' own rows: the two-DOF
    oscillator's 62 of 155 coordinates) the elimination runs compiled, over the nonzero
    couplings (:func:`_reduce_diagonal`: 0.65 -> 0.2 ms there, the same Schur complement
    summed over its nonzero terms only)."""
    dyn_, alg, B0, B1, B2, back, done = _reduce_diagonal(A0, A1, A2)
    if alg.size and not done:
        try:
            back = -np.linalg.solve(A0[np.ix_(alg, alg)], A0[np.ix_(alg, dyn_)])
        except np.linalg.LinAlgError:
            back = -np.linalg.lstsq(A0[np.ix_(alg, alg)], A0[np.ix_(alg, dyn_)],
                                    rcond=None)[0]
        B0 = B0 + A0[np.ix_(dyn_, alg)] @ back
    if not alg.size:
        back = None
    blocks = None
    if dyn_.size <= MIN_BLOCK:  # _components' answer, whatever the hint
        blocks = [np.arange(dyn_.size)] if dyn_.size else []
    elif hint is not None and np.array_equal(hint.dyn, dyn_):
        blocks = hint.blocks if _decouples(B0, B1, B2, hint.blocks) else None
    if blocks is None:
        blocks = _components(B0, B1, B2) if dyn_.size else []
    return QuadraticReduction(A0.shape[0], dyn_, alg, back, B0, B1, B2, blocks)


@njit(cache=True)
def _reduce_diagonal(A0, A1, A2):
    """:func:`reduce_quadratic`'s coordinate sets ``dyn`` (a row or column of ``A1`` or
    ``A2`` nonzero) and ``alg``, the three matrices on ``dyn``, and where ``A0``'s algebraic
    block is diagonal with no zero on it, the elimination: ``back = -A0[alg, alg]^-1
    A0[alg, dyn]`` and ``B0 += A0[dyn, alg] back`` over the nonzero entries of
    ``A0[dyn, alg]``. Returns ``(dyn, alg, B0, B1, B2, back, done)``; ``done`` False (``B0``
    not yet reduced) where the block is not diagonal."""
    n = A0.shape[0]
    has = np.zeros(n, dtype=np.bool_)
    for i in range(n):
        for j in range(n):
            if A1[i, j] != 0 or A2[i, j] != 0:
                has[i] = True
                has[j] = True
    dyn = np.flatnonzero(has)
    alg = np.flatnonzero(~has)
    nd, na = dyn.size, alg.size
    B0 = np.empty((nd, nd))
    B1 = np.empty((nd, nd))
    B2 = np.empty((nd, nd))
    for a in range(nd):
        for b in range(nd):
            B0[a, b] = A0[dyn[a], dyn[b]]
            B1[a, b] = A1[dyn[a], dyn[b]]
            B2[a, b] = A2[dyn[a], dyn[b]]
    back = np.zeros((na, nd))
    for a in range(na):
        if A0[alg[a], alg[a]] == 0:
            return dyn, alg, B0, B1, B2, back, na == 0
        for b in range(na):
            if a != b and A0[alg[a], alg[b]] != 0:
                return dyn, alg, B0, B1, B2, back, False
    for a in range(na):
        piv = A0[alg[a], alg[a]]
        for b in range(nd):
            back[a, b] = -(A0[alg[a], dyn[b]] / piv)
    for i in range(nd):
        for a in range(na):
            f = A0[dyn[i], alg[a]]
            if f != 0:
                for b in range(nd):
                    B0[i, b] += f * back[a, b]
    return dyn, alg, B0, B1, B2, back, True


def _decouples(B0: np.ndarray, B1: np.ndarray, B2: np.ndarray, blocks: list) -> bool:
    """Whether ``B0 + s B1 + s^2 B2`` has no entry coupling two of ``blocks`` (the test of
    :func:`_components`: none above :data:`DECOUPLED_TOL` times the largest of its matrix)."""
    label = np.empty(B0.shape[0], dtype=np.int64)
    for i, b in enumerate(blocks):
        label[b] = i
    return all(_decoupled(X, label, DECOUPLED_TOL) for X in (B0, B1, B2))


@njit(cache=True)
def _decoupled(X, label, tol):
    """No entry of ``X`` between coordinates of different ``label`` above ``tol`` times
    its largest (:func:`_decouples` compiled, one matrix)."""
    n = X.shape[0]
    big = 0.0
    for i in range(n):
        for j in range(n):
            big = max(big, abs(X[i, j]))
    if big == 0:
        return True
    for i in range(n):
        for j in range(n):
            if label[i] != label[j] and abs(X[i, j]) > tol * big:
                return False
    return True


def quadratic_eigen(A0: np.ndarray, A1: np.ndarray, A2: np.ndarray):
    """Eigenvalues (k,) and eigenvectors (n, k) of ``(A0 + s A1 + s^2 A2) y = 0``.

    Algebraic coordinates are eliminated (:func:`reduce_quadratic`). The rest is linearised
    as ``[[0, I], [-A2^-1 A0, -A2^-1 A1]]`` (a standard real eigenvalue problem) when ``A2``
    is well conditioned there, else as the generalised problem of the companion pencil
    (infinite eigenvalues are dropped)."""
    return dense_eigen(reduce_quadratic(A0, A1, A2))


def dense_eigen(red: QuadraticReduction):
    """Every eigenpair of a :class:`QuadraticReduction` (:func:`quadratic_eigen`), block by
    block."""
    nd = red.dyn.size
    if nd == 0:
        return np.zeros(0, dtype=complex), np.zeros((red.n, 0), dtype=complex)
    parts = []
    for comp in red.blocks:
        ix = np.ix_(comp, comp)
        v, Yc = _companion_eigen(red.B0[ix], red.B1[ix], red.B2[ix])
        Y = np.zeros((nd, v.size), dtype=complex)
        Y[comp] = Yc
        parts.append((v, Y))
    vals = np.concatenate([v for v, _ in parts])
    Y = np.hstack([y for _, y in parts])
    return vals, red.full(Y)


def _inverse_iteration(B0, B1, B2, sigma: complex, y: np.ndarray, max_iter: int = 10,
                       split: tuple | None = None, norms: np.ndarray | None = None):
    """The eigenpair of ``(B0 + s B1 + s^2 B2) y = 0`` nearest ``(sigma, y)``: one step of
    inverse iteration with ``P(sigma)`` (the start vector turned towards the eigenvector of
    the eigenvalue nearest ``sigma``), then the nonlinear inverse iteration (Ruhe, SIAM J.
    Numer. Anal. 10, 1973, section 3: ``u = P(s)^-1 P'(s) x``, ``s <- s - (v^H x) / (v^H u)``,
    quadratically convergent to a simple eigenvalue), one LU of ``P(s)`` a step. Returns
    ``(sigma, y, converged)``; converged when the step is below 1e-14 of ``max(1, |sigma|)``
    (the rounding of the dense eigensolver's eigenvalue, whose backward error is of the same
    order), or when the quadratic convergence predicts the next step below 1e-15 of it
    (:func:`_settled`: the step that would only confirm it is not taken); after a step
    within :data:`KEPT_FROM` of it, the next steps on that step's LU until the pair's
    backward error is at rounding (:data:`COPY_EXACT`; :func:`_ruhe`'s ``reuse``, the
    compiled path). Compiled: with ``split``
    (:func:`~fretwear.hb.hill_tracking.harmonic_split` of the block: unknowns that couple
    only their own harmonic), each step by the LU of the core's Schur complement
    (:func:`_ruhe`: 31 instead of 62 unknowns on the two-DOF oscillator's block, 0.18
    against 0.38 ms a call there); otherwise up to :data:`PAIR_COMPILED_MAX` unknowns with
    its own LU, beyond with LAPACK's solve called from a kernel of its own
    (:func:`_ruhe_lapack`: 0.40 against 0.63 ms for the steps called from Python on that
    block); the steps from Python (:func:`_inverse_iteration_py`) where that solve meets a
    singular ``P(s)``. ``norms``: :func:`_column_norms` of the three matrices (made here
    without)."""
    real = all(np.isrealobj(b) for b in (B0, B1, B2))  # real: half the work a product
    B0, B1, B2 = (np.ascontiguousarray(b, dtype=float if real else complex)
                  for b in (B0, B1, B2))
    y = np.ascontiguousarray(y, dtype=complex)
    split = no_split() if split is None else split
    if B0.shape[0] > PAIR_COMPILED_MAX and split[0].size + split[2].size == 0:
        try:
            s1, x1, ok = _ruhe_lapack(B0, B1, B2, complex(sigma), y, max_iter)
        except np.linalg.LinAlgError:  # LAPACK's solve at a singular P(s)
            return _inverse_iteration_py(B0, B1, B2, sigma, y, max_iter)
        return complex(s1), x1, bool(ok)
    norms = _column_norms(B0, B1, B2) if norms is None else norms
    s1, x1, ok = _ruhe(B0, B1, B2, complex(sigma), y, max_iter, split, REUSE_MAX, norms)
    return complex(s1), x1, bool(ok)


def _inverse_iteration_py(B0, B1, B2, sigma: complex, y: np.ndarray, max_iter: int = 10):
    """:func:`_inverse_iteration`'s steps from Python with LAPACK's ``zgetrf``/``zgetrs``
    (not converged at a zero pivot)."""
    x = y / np.linalg.norm(y)
    first = True
    last = np.inf
    for _ in range(max_iter):
        P = sigma * B1  # B0 + sigma B1 + sigma^2 B2, the same sums without temporaries
        P += B0
        P += (sigma * sigma) * B2
        lu, piv, info = zgetrf(P, overwrite_a=True)
        if info != 0:
            return sigma, x, False
        if first:  # towards the eigenvector of the eigenvalue nearest sigma
            x = zgetrs(lu, piv, x)[0]
            x = x / np.linalg.norm(x)
            first = False
        u = zgetrs(lu, piv, (B1 + (2.0 * sigma) * B2) @ x)[0]
        den = np.vdot(x, u)
        if not np.isfinite(den) or den == 0:
            return sigma, x, False
        step = 1.0 / den
        sigma = complex(sigma - step)
        x = u / np.linalg.norm(u)
        if _settled(abs(step), last, max(1.0, abs(sigma))):
            return sigma, x, True
        last = abs(step)
    return sigma, x, False


def track_eigen(red: QuadraticReduction, track: HillTrack | None, shape: tuple,
                omega: float | None = None):
    """The centred members (``|kappa| <= 1/2``, ``Im s >= 0``) of every family of
    ``(A0 + s A1 + s^2 A2) y = 0`` continued from those of a neighbouring solution
    (:class:`HillTrack`) by inverse iteration (:func:`_inverse_iteration`), or None where that
    is not shown to give the set that :func:`dense_eigen` and the centroid rule keep
    (``shape``: ``(m + q, H, k)`` of :func:`centroid`):

    * the problem has the same coordinates and blocks as at the neighbour, and every family
      was represented there (``track.complete``);
    * every member converges (to the dense eigensolver's eigenvalue, to its rounding) with
      ``|kappa| <= 1/2``, ``Im s >= 0``, below the magnitude cut, on the period-doubling line
      ``Im s = w/2`` (within :data:`EDGE_TOL`), near it or off it (:func:`_on_line`), not at
      the threshold between the two;
    * two members that converge to one eigenvalue count once (the two real negative
      multipliers of a period doubling meeting into a complex pair near the line);
    * the mirror ``conj(s) + i`` of a member on or near the line (the member of the
      conjugate family across the line) is the member itself, or another eigenvalue: one on
      the line with ``|kappa| <= 1/2`` is a member (the second real negative multiplier born
      where a complex pair met on the line), any other one the dense path would not keep
      (:func:`_may_keep`);
    * they number the families of the truncated problem, ``2 nd / H`` (``nd`` coordinates with
      a mass; a complex member off the line stands for two, its conjugate being another
      family's; a real one or one on the line for one): every family is represented;
    * the copy ``s + i sign(kappa)`` of each (the neighbour in its family on the side of the
      tie at ``|kappa| = 1/2``; a copy ``s + i j`` has the centroid ``kappa - j``) is one
      that the dense path would not keep (:func:`_may_keep`: ``|kappa| > 1/2`` and not a
      period-doubling member that :func:`_edge_members` may add, with a margin for
      rounding): no family has a second member that the rule keeps (copies further off
      have ``|kappa| >= 3/2`` less their truncation). The copy is the member's eigenvector
      moved by one harmonic, taken as it is where that pair's backward error is at rounding
      (:data:`COPY_EXACT`, :func:`_copy`), otherwise iterated from there.

    The blocks' arrays are gathered once per point (:func:`_block_mats`).

    ``omega``: the solution's circular frequency, with the track's velocities the start of
    each member's iteration (a member moved 2-3e-2 a step on the benchmark's two-DOF sweep:
    4-6 LU steps from the neighbour's eigenvalue, fewer from the extrapolated one; the
    sweep's LU factorisations 1081 -> 935).

    Returns ``(vals, vecs, kap, origin)``: ``vals``, ``vecs`` as :func:`dense_eigen`, the
    members only, with their centroids, and per member the index of the neighbour's member it
    continues (-1: a mirror found here)."""
    if track is None or not track.complete or red.dyn.size != track.nd:
        return None
    if not np.array_equal(red.dyn, track.dyn) or len(red.blocks) != len(track.blocks) or any(
            not np.array_equal(a, b) for a, b in zip(red.blocks, track.blocks, strict=True)):
        return None
    r, H, k = shape
    cut = 2.0 * (k + 1) + 10.0
    nd = red.dyn.size
    members = []  # (s, y on the block, kappa, block, neighbour's index)
    mats: dict = {}  # per block, its complex matrices (made once)
    step = 0.0 if omega is None or track.omega is None else omega - track.omega
    for j, (s0, b) in enumerate(zip(track.sigma, track.block, strict=True)):
        starts = [complex(s0)]
        if track.velocity is not None and abs(track.velocity[j] * step) < 0.1:
            # the member's own motion, extrapolated; the neighbour's eigenvalue where the
            # iteration from there does not converge
            starts.insert(0, complex(s0 + track.velocity[j] * step))
        for s0 in starts:
            got = _member(red, b, s0, track.Y[red.blocks[b], j], shape, mats)
            if got is not None:
                break
        if got is None:
            return None
        s1, y, kp = got
        if abs(kp) > 0.5 or abs(s1) > 0.9 * cut or _on_line(s1) is None:
            return None
        if any(abs(s1 - m[0]) <= 1e-8 * max(1.0, abs(s1)) for m in members):
            continue  # a second start converged to the same member (a pair met)
        members.append((s1, y, kp, b, j))
    todo = list(range(len(members)))
    while todo:  # each member's neighbouring copy, and the mirror of those near the line
        s1, y, kp, b, j = members[todo.pop(0)]
        side = 1 if kp >= 0 else -1
        starts = [(s1, y, False)]  # the copy, from the member itself (_copy)
        if _on_line(s1) != "off":
            starts.append((s1.conjugate() + 1j, y.conj(), True))
        if _on_line(s1) == "on" and j >= 0 and _on_line(complex(track.sigma[j])) != "on":
            # landed on the line from a complex pair: the pair's other member, from the
            # mirror of the neighbour's
            y0 = track.Y[red.blocks[b], j]
            starts.append((complex(track.sigma[j]).conjugate() + 1j, y0.conj(), True))
        for sn, y0, mirror in starts:
            if mirror:
                got = _member(red, b, sn, y0, shape, mats, fold=False)
            else:  # the copy s + i side
                got = _copy(red, b, sn, y0, shape, mats, side)
            if got is None:
                return None
            s2, y2, kn = got[:3]
            vals = np.array([m[0] for m in members])
            if np.min(np.abs(vals - s2)) <= 1e-8 * max(1.0, abs(s2)):
                continue  # a member (the mirror of one on the line is itself)
            if (mirror and _on_line(s2) == "on" and abs(kn) <= 0.5 and s2.imag > 0
                    and abs(s2) <= 0.9 * cut):
                members.append((s2, y2, kn, b, -1))  # the other real negative multiplier
                todo.append(len(members) - 1)
            elif _may_keep(s2, kn, vals):
                return None  # another member the rule may keep (or nearly)
    vals = np.array([m[0] for m in members], dtype=complex)
    single = (vals.imag == 0.0) | np.array([_on_line(v) == "on" for v in vals], dtype=bool)
    if int(np.sum(np.where(single, 1, 2))) * H != 2 * nd:
        return None
    Y = np.zeros((nd, vals.size), dtype=complex)
    for j, m in enumerate(members):
        Y[red.blocks[m[3]], j] = m[1]
    return (vals, red.full(Y), np.array([m[2] for m in members]),
            np.array([m[4] for m in members], dtype=int))


def _shifted_copy(red: QuadraticReduction, b: int, y: np.ndarray, shape: tuple,
                  side: int) -> np.ndarray:
    """The eigenvector ``y`` (on block ``b`` of ``red``) of a member ``s`` moved to its copy
    ``s + i side`` (``p e^{-i side w t}``: complex-exponential coefficient ``n`` from
    ``n + side``, harmonic orders as their index among the kept harmonics, as
    :func:`centroid` takes them): the copy's eigenvector up to the truncation, the start of
    the inverse iteration that finds the copy (:func:`track_eigen`). Compiled, on the block's
    coordinates only (:func:`~fretwear.hb.hill_tracking.shift_block`: the shift acts on each
    coordinate alone; the same vector as shifting the whole eigenvector and restricting)."""
    r, H, k = shape
    idx = np.ascontiguousarray(red.dyn[red.blocks[b]], dtype=np.int64)
    v = shift_block(np.ascontiguousarray(y, dtype=complex), idx, H, k, side)
    nrm = np.linalg.norm(v)
    return v / nrm if nrm > 0 else y


def _block_mats(red: QuadraticReduction, b: int, shape: tuple, mats: dict) -> tuple:
    """Block ``b``'s arrays for :func:`_member` and :func:`_copy` (made on the block's first
    use, kept in ``mats``): its ``B0, B1, B2`` (real: in the kernels the pencil's sums take
    a real entry times the complex ``sigma``), the harmonic split, the block's coordinates,
    the algebraic coordinates' ``back`` restricted to the block (an empty one without), the
    algebraic coordinates, and the matrices' column norms (:func:`_column_norms`)."""
    if b not in mats:
        r, H, k = shape
        comp = np.ascontiguousarray(red.blocks[b], dtype=np.int64)
        back = np.zeros((0, red.dyn.size)) if red.back is None else red.back
        *real, back, at, harm = _gather_block(red.B0, red.B1, red.B2, comp, back, red.dyn, H, k)
        split = split_of(*real, harm, DECOUPLED_TOL, SPLIT_MAX_SHARE)
        alg = np.ascontiguousarray(red.alg, dtype=np.int64)
        mats[b] = (tuple(real), split, at, back, alg, _column_norms(*real))
    return mats[b]


def _member(red: QuadraticReduction, b: int, s0: complex, y0: np.ndarray, shape: tuple,
            mats: dict, fold: bool = True):
    """The eigenpair of block ``b`` of ``red`` nearest ``(s0, y0)`` by inverse iteration
    (:func:`_inverse_iteration`), and its centroid (:func:`_block_centroid`). ``fold`` (a
    member): a real one made exactly real, one below the real axis replaced by its
    conjugate, and where the centre moved to the next copy (``|kappa| > 1/2``), that copy
    ``s + i round(kappa)`` instead; otherwise (a neighbouring copy or a mirror) the
    eigenpair as found. None where an iteration does not converge. ``mats``: the blocks'
    arrays made so far (:func:`_block_mats`)."""
    r, H, k = shape
    B, split, at, back, alg, norms = _block_mats(red, b, shape, mats)
    for again in (False, True):
        s1, y, ok = _inverse_iteration(*B, s0, y0, split=split, norms=norms)
        if not ok:
            return None
        if fold and abs(s1.imag) <= 1e-12 * max(abs(s1), 1.0):
            s1 = complex(s1.real, 0.0)
        if fold and s1.imag < 0:  # the conjugate pair's other member
            s1, y = s1.conjugate(), y.conj()
        kp = float(_block_centroid(y, at, back, alg, red.n, r, H, k))
        if again or not fold or abs(kp) <= 0.5:
            return s1, y, kp
        s0, y0 = s1 + 1j * round(kp), y  # the centre moved to the next copy


def _copy(red: QuadraticReduction, b: int, s1: complex, y: np.ndarray, shape: tuple,
          mats: dict, side: int):
    """The neighbouring copy ``s + i side`` of the member ``(s1, y)`` of block ``b``:
    ``(s, y, kappa, certified)``, None where its inverse iteration does not converge.
    Its start ``(sigma, v)`` (:func:`_copy_start`): ``sigma = s1 + i side``, ``v`` the
    member's eigenvector moved by one harmonic (:func:`_shifted_copy`, normalised). The
    shift maps the untruncated Hill problem at ``s`` onto itself at ``s + i``, so
    ``P(sigma) v`` is the truncation's part only: the member's residual (rounding) plus the
    rows where the law couples the harmonic that left or entered the kept ones. Where the
    law does not reach them (a block whose coordinates' laws do not vary over the period,
    or an eigenvector with no weight at the edge harmonics) that is rounding too. Where the
    backward error of ``(sigma, v)`` (:func:`_backward_error`) is below :data:`COPY_EXACT`
    the pair is an exact eigenpair of a pencil ``P + E`` with ``|E| <= COPY_EXACT |P|`` (to
    the rounding of the computed residual itself, about ``n u |P| |v|``), no further from
    ``P`` than the eigenpairs that the dense eigensolver (backward stable on the companion
    form) or the inverse iteration (stopped at a step below 1e-14) return: the copy is
    certified as it is, with its centroid, and no inverse iteration is
    run; otherwise the inverse iteration from it (:func:`_member`, not folded)."""
    r, H, k = shape
    B, split, at, back, alg, norms = _block_mats(red, b, shape, mats)
    sigma, v, eta = _copy_start(*B, norms, complex(s1), np.ascontiguousarray(y, dtype=complex),
                                side, at, H, k)
    if eta <= COPY_EXACT:
        return complex(sigma), v, float(_block_centroid(v, at, back, alg, red.n, r, H, k)), True
    got = _member(red, b, sigma, v, shape, mats, fold=False)
    return None if got is None else got + (False,)


@njit(cache=True)
def _copy_start(B0, B1, B2, norms, s1, y, side, at, H, k):
    """:func:`_copy`'s start ``(sigma, v)`` and its backward error, compiled: ``v``
    :func:`~fretwear.hb.hill_tracking.shift_block` of ``y`` normalised (``y`` where the
    shift leaves nothing), ``sigma = s1 + i side``."""
    v = shift_block(y, at, H, k, side)
    nrm = 0.0
    for i in range(v.size):
        nrm += v[i].real * v[i].real + v[i].imag * v[i].imag
    v = v / np.sqrt(nrm) if nrm > 0 else y.copy()
    sigma = s1 + 1j * side
    return sigma, v, _backward_error(B0, B1, B2, sigma, v, norms)


@njit(cache=True)
def _gather_block(B0, B1, B2, comp, back, dyn, H, k):
    """Block ``comp`` (indices into ``dyn``) of the reduction's matrices in one compiled
    call (:func:`_block_mats`): the three (real) blocks, the columns
    ``comp`` of ``back``, the block's coordinates ``dyn[comp]`` and their harmonics (the
    coefficient index ``0, a_1..a_k, b_1..b_k`` of each, folded to ``0..k``)."""
    nb = comp.size
    R0, R1, R2 = np.empty((nb, nb)), np.empty((nb, nb)), np.empty((nb, nb))
    for a in range(nb):
        for c in range(nb):
            R0[a, c] = B0[comp[a], comp[c]]
            R1[a, c] = B1[comp[a], comp[c]]
            R2[a, c] = B2[comp[a], comp[c]]
    bk = np.empty((back.shape[0], nb))
    for a in range(back.shape[0]):
        for c in range(nb):
            bk[a, c] = back[a, comp[c]]
    at = np.empty(nb, dtype=np.int64)
    harm = np.empty(nb, dtype=np.int64)
    for a in range(nb):
        at[a] = dyn[comp[a]]
        c = at[a] % H
        harm[a] = c - k if c > k else c
    return R0, R1, R2, bk, at, harm


@njit(cache=True)
def _block_centroid(y, at, back, alg, n, r, H, k):
    """:func:`centroid` of the eigenvector ``y`` on a block's coordinates ``at`` with the
    algebraic coordinates ``alg`` recovered as ``back @ y`` (:meth:`QuadraticReduction.full`
    restricted to the block)."""
    p = np.zeros(n, dtype=np.complex128)
    for i in range(at.size):
        p[at[i]] = y[i]
    for a in range(alg.size):
        acc = 0j
        for j in range(y.size):
            acc += back[a, j] * y[j]
        p[alg[a]] = acc
    return _centroids(p.reshape(1, r, H), k)[0]


@njit(cache=True)
def _column_norms(B0, B1, B2):
    """The largest column 2-norm of each of ``B0, B1, B2``: a lower bound of its 2-norm
    (:func:`_backward_error`'s denominator, made once per block)."""
    n = B0.shape[0]
    c0, c1, c2 = 0.0, 0.0, 0.0
    for j in range(n):
        a0, a1, a2 = 0.0, 0.0, 0.0
        for i in range(n):
            a0 += B0[i, j].real ** 2 + B0[i, j].imag ** 2
            a1 += B1[i, j].real ** 2 + B1[i, j].imag ** 2
            a2 += B2[i, j].real ** 2 + B2[i, j].imag ** 2
        c0, c1, c2 = max(c0, a0), max(c1, a1), max(c2, a2)
    return np.array([np.sqrt(c0), np.sqrt(c1), np.sqrt(c2)])


@njit(cache=True)
def _backward_error(B0, B1, B2, sigma, v, norms):
    """The backward error of the pair ``(sigma, v)`` of ``B0 + s B1 + s^2 B2`` (Tisseur,
    Linear Algebra Appl. 309, 2000, theorem 1: ``|P(sigma) v| / ((|B0| + |sigma| |B1| +
    |sigma|^2 |B2|) |v|)``), with ``norms`` (:func:`_column_norms`: each matrix's largest
    column 2-norm, a lower bound of its 2-norm, so the error is not under-estimated by the
    norms; the computed residual ``P(sigma) v`` carries its own rounding, about ``n u`` of
    the denominator, so the value is Tisseur's to that rounding) for the matrices' 2-norms.
    """
    n = B0.shape[0]
    s2 = sigma * sigma
    res = 0.0
    nv = 0.0
    for i in range(n):
        acc = 0j
        for j in range(n):
            acc += (B0[i, j] + sigma * B1[i, j] + s2 * B2[i, j]) * v[j]
        res += acc.real * acc.real + acc.imag * acc.imag
        nv += v[i].real * v[i].real + v[i].imag * v[i].imag
    den = (norms[0] + abs(sigma) * norms[1] + abs(sigma) ** 2 * norms[2]) * np.sqrt(nv)
    return np.sqrt(res) / den if den > 0 else np.inf


def _on_line(s: complex) -> str | None:
    """Where the member ``s`` (``s / w``, ``Im s >= 0``) lies from the period-doubling line
    ``Im s = 1/2``: ``"on"`` within :data:`EDGE_TOL` (a real negative multiplier, one family:
    :func:`hill_stability` counts it once), ``"near"`` up to :data:`EDGE_KAPPA` (a complex
    pair close to meeting on the line, where :func:`_edge_members` may act), ``"off"``
    beyond; None within :data:`KAPPA_MARGIN` of :data:`EDGE_TOL` (a member whose count the
    rounding could change: not continued).

    On the line the truncated problem has one eigenvalue per real negative multiplier (the
    members ``a + i/2`` of the two families born where a complex pair met; measured on the
    two-DOF unilateral oscillator's sweep): simple and apart from each other, so inverse
    iteration continues each as it continues any member. On and near the line, the mirror
    ``conj(s) + i`` (the member of the conjugate family across the line: the same
    eigenvalue on it) is the neighbour the dense path's selection could also keep, so
    :func:`track_eigen` checks it as it checks the neighbouring copies."""
    dist = abs(abs(s.imag) - 0.5)
    if abs(dist - EDGE_TOL) <= KAPPA_MARGIN:
        return None
    if dist <= EDGE_TOL:
        return "on"
    return "near" if dist <= EDGE_KAPPA else "off"


def _may_keep(s: complex, kap: float, kept: np.ndarray) -> bool:
    """Whether the dense path's selection (:func:`hill_stability`: ``|kappa| <= 1/2`` and
    ``Im s >= 0``, or a member :func:`_edge_members` may add) could keep the eigenvalue ``s``
    (in ``s / w``) of centroid ``kap``, with :data:`KAPPA_MARGIN` on every threshold (``s``
    and ``kap`` found by inverse iteration differ from the dense eigensolver's by rounding).
    ``kept``: members the centroid rule keeps (``Im s >= 0``; their conjugates are kept too):
    :func:`_edge_members` adds no member within :data:`EDGE_KAPPA` of one of them or of its
    conjugate (the mirror of a member near the period-doubling line, :func:`_on_line`)."""
    if s.imag < -KAPPA_MARGIN * max(abs(s), 1.0):
        return False
    if abs(kap) <= 0.5 + KAPPA_MARGIN:
        return True
    if not (abs(abs(s.imag) - 0.5) <= EDGE_KAPPA + KAPPA_MARGIN
            and abs(kap) <= 0.5 + EDGE_KAPPA + KAPPA_MARGIN):
        return False
    d = np.minimum(np.abs(kept - s), np.abs(kept - np.conj(s)))
    return not bool(np.any(d <= EDGE_KAPPA - KAPPA_MARGIN))


def _track_record(red: QuadraticReduction, vals: np.ndarray, vecs: np.ndarray,
                  kap: np.ndarray, edge: np.ndarray, H: int, cut: float):
    """The :class:`HillTrack` of the kept members ``vals`` (``Im s >= 0``) with their
    eigenvectors ``vecs`` (n, k), centroids ``kap`` and edge flags, None where it cannot be
    continued (an edge member or one near the period-doubling line, a member near the
    magnitude cut ``cut``, or one spread over two blocks). The members are few (a handful):
    their tests run on Python scalars, and where the problem is one block every member lies
    in it (no shares to compare)."""
    nd = red.dyn.size
    if nd == 0 or edge.any():
        return None
    for x in kap.tolist():
        if abs(x) > 0.5:
            return None
    families = 0
    for v in vals.tolist():
        line = _on_line(v)
        if line is None or abs(v) > 0.9 * cut:
            return None
        real = abs(v.imag) <= 1e-12 * max(abs(v), 1.0)
        families += 1 if (real or line == "on") else 2
    Y = vecs[red.dyn]
    blocks = red.blocks
    if len(blocks) == 1 and blocks[0].size == nd:  # the whole of every member: its share
        block = np.zeros(vals.size, dtype=np.intp)  # is its squared norm
    else:
        sq = Y.real ** 2 + Y.imag ** 2  # each member's share of each block (squared norms)
        share = np.array([sq[c].sum(axis=0) for c in blocks]).reshape(len(blocks), vals.size)
        block = np.argmax(share, axis=0)
        if np.any(share[block, np.arange(vals.size)] < (1.0 - 1e-12) ** 2 * sq.sum(axis=0)):
            return None
    complete = 2 * nd == families * H
    return HillTrack(vals.copy(), Y, block, nd, red.dyn.copy(), [b.copy() for b in blocks],
                     complete)


def _components(B0: np.ndarray, B1: np.ndarray, B2: np.ndarray) -> list:
    """The index sets of the blocks into which ``B0 + s B1 + s^2 B2`` decouples (the connected
    components of its pattern; entries below :data:`DECOUPLED_TOL` times the largest of their
    matrix are rounding, e.g. of ``P Q = I`` where a coordinate's law is time-invariant). A
    coordinate whose law does not vary over the period (a contact point open, sliding without
    memory, or a held structure) couples no harmonics, so its harmonics decouple: the dense
    eigensolve, ``O(n^3)``, runs on the blocks (those smaller than :data:`MIN_BLOCK` together)."""
    if B0.shape[0] <= MIN_BLOCK:
        return [np.arange(B0.shape[0])]
    pattern = np.zeros(B0.shape, dtype=bool)
    for X in (B0, B1, B2):
        big = np.abs(X).max(initial=0.0)
        if big > 0:
            pattern |= np.abs(X) > DECOUPLED_TOL * big
    # a sparse pattern: the dense one goes through csgraph's masked-array validation
    count, label = connected_components(csr_matrix(pattern), directed=False)
    blocks, group, size = [], [], 0
    for c in range(count):  # small blocks are solved together, up to MIN_BLOCK unknowns (a
        idx = np.flatnonzero(label == c)  # call costs more than the flops saved)
        if idx.size >= MIN_BLOCK:
            blocks.append(idx)
            continue
        if size + idx.size > MIN_BLOCK:
            blocks.append(np.concatenate(group))
            group, size = [], 0
        group.append(idx)
        size += idx.size
    if group:
        blocks.append(np.concatenate(group))
    return blocks


def _companion_eigen(B0: np.ndarray, B1: np.ndarray, B2: np.ndarray):
    """Eigenvalues and eigenvectors of ``(B0 + s B1 + s^2 B2) y = 0`` (every coordinate with
    a mass): the companion linearisation (:func:`quadratic_eigen`)."""
    nd = B0.shape[0]
    eye, nil = np.eye(nd), np.zeros((nd, nd))
    lu, piv, info = dgetrf(B2)
    cond = np.inf
    if info == 0 and np.all(np.isfinite(lu)):
        # LAPACK's estimate of the 1-norm condition number from the LU that the solve below
        # reuses (an SVD's 2-norm one cost as much as the eigensolve on a truncated beam's
        # blocks of 105 unknowns); the two differ by at most a factor nd
        rcond, _ = dgecon(lu, np.linalg.norm(B2, 1), norm="1")
        cond = 1.0 / rcond if rcond > 0 else np.inf
    if cond < 1e10:
        top, _ = dgetrs(lu, piv, np.hstack([B0, B1]))
        vals, Y = np.linalg.eig(np.block([[nil, eye], [-top[:, :nd], -top[:, nd:]]]))
    else:
        vals, Y = sla.eig(np.block([[nil, eye], [-B0, -B1]]),
                          np.block([[eye, nil], [nil, B2]]), check_finite=False)
        ok = np.isfinite(vals)
        vals, Y = vals[ok], Y[:, ok]
    return vals, Y[:nd]


def _edge_members(vals: np.ndarray, kap: np.ndarray, keep: np.ndarray) -> np.ndarray:
    """Members of a period-doubling family that the centroid rule drops: at ``Im s = w/2``
    the family's two members ``s`` and ``conj(s) = s - i w`` tie at ``|kappa| = 1/2``, and the
    truncation can put both a little above it (0.507 on the unilateral oscillator with 15
    harmonics, where the pair carried a multiplier of -1.23 that the time integration finds
    too). Such a member (``|Im s / w - 1/2| <= EDGE_KAPPA``, ``|kappa| <= 1/2 + EDGE_KAPPA``,
    ``Im s >= 0``) is kept when neither it nor its conjugate is near a kept exponent."""
    sig = vals
    near_edge = ((np.abs(np.abs(sig.imag) - 0.5) <= EDGE_KAPPA)
                 & (np.abs(kap) <= 0.5 + EDGE_KAPPA) & ~keep & (sig.imag >= 0))
    out = np.zeros_like(keep)
    kept = sig[keep]
    for i in np.flatnonzero(near_edge):
        d = np.minimum(np.abs(kept - sig[i]), np.abs(kept - np.conj(sig[i])))
        if not np.any(d <= EDGE_KAPPA):
            out[i] = True
            kept = np.append(kept, sig[i])
    return out


#: steps of Ruhe's iteration on the LU of a step before (:func:`_kept_step`), after a step
#: within :data:`KEPT_FROM` of the eigenvalue, before a new LU is made
REUSE_MAX = 6
#: a Ruhe step below this (relative to ``max(1, |sigma|)``) keeps its LU for the next steps
#: (:func:`_may_reuse`)
KEPT_FROM = 1e-4
#: a step on a kept LU must be below this times the step before it; otherwise a new LU
#: (the contraction goes with the kept shift's distance to the eigenvalue)
KEPT_CONTRACTION = 1e-2
#: :func:`_pair` runs compiled (:func:`_pair_small`) up to this many unknowns (a refinement
#: on a small model, where the calls of an LU and its solves cost more than their flops:
#: 2.4 against 30 us at 5 unknowns, 25 against 54 us at 30), LAPACK's LU beyond (as fast
#: at 64)
PAIR_COMPILED_MAX = 48


@njit(cache=True)
def _unit(y):
    """``y / |y|`` (2-norm)."""
    nrm = 0.0
    for i in range(y.size):
        nrm += y[i].real * y[i].real + y[i].imag * y[i].imag
    return y / np.sqrt(nrm)


@njit(cache=True)
def _pair_small(T, v, mu0, steps):
    """:func:`_pair` compiled: the LU of ``T - mu0 I`` with partial pivoting, ``steps``
    solves from ``v``, the Rayleigh quotient. Returns ``(mu, y, ok)``; ``ok`` False at a zero
    pivot (LAPACK's path then runs)."""
    n = T.shape[0]
    A = T.copy()
    for i in range(n):
        A[i, i] -= mu0
    piv, ok = _lu_small(A)
    if not ok:
        return 0j, v, False
    y = _unit(v)
    for _ in range(steps):
        y = _unit(_lu_solve_small(A, piv, y))
    mu = 0j
    for i in range(n):
        acc = 0j
        for j in range(n):
            acc += T[i, j] * y[j]
        mu += np.conj(y[i]) * acc
    return mu, y, True


@njit(cache=True)
def _residuals(T, y, mu, floor):
    """``(max(|mu|, |T y - mu y|) / |T|, |T y - mu y| / |T|)`` with the 1-norm of ``T``
    (:meth:`HillProblem.evaluate`: the stopping rule of :func:`_track`) in one call; the
    1-norm at least ``floor`` (the column sums of a block left out, :func:`_evaluate`)."""
    n = T.shape[0]
    scale = floor
    for j in range(n):
        col = 0.0
        for i in range(n):
            col += abs(T[i, j])
        scale = max(scale, col)
    r2 = 0.0
    for i in range(n):
        acc = 0j
        for j in range(n):
            acc += T[i, j] * y[j]
        acc -= mu * y[i]
        r2 += acc.real * acc.real + acc.imag * acc.imag
    pair = np.sqrt(r2) / scale
    return max(abs(mu) / scale, pair), pair


@njit(cache=True)
def _evaluate(Gc, node, start, length, rows, P, z, Kf, Mf, Cf, Df, m, harmonics, omega,
              sigma, eps, v, mu0, steps, keep, dropped, form):
    """:meth:`HillProblem.evaluate` in one compiled call where ``G(s)`` is split
    (:mod:`fretwear.hb.memory_gain`) and every piece runs compiled: ``G(s)``
    (:func:`fretwear.hb.memory_gain._gain_at`, ``z = e^{-s h}``), ``Z_r``
    (:func:`_condensed_at`), ``T(s)`` (:func:`_hill_matrix`), the pair (:func:`_pair_small`)
    and the residuals (:func:`_residuals`): the same kernels as the calls one by one (the same
    values), one call's overhead instead of five. ``keep``: the unknowns the pair and the
    residuals work on where the others are decoupled (:func:`_decoupled_normals`: ``T(s)``
    block-diagonal, a block that does not vanish on the others) and the start ``v`` is zero
    on the others: the pair's LU with partial pivoting, its solves and the residuals then
    take the same values as on the whole matrix (the dropped block factored apart, its
    exact zeros adding nothing; the dropped columns' sums in the 1-norm), on a quarter of
    the entries (a Jenkins point's pair 38 -> 10 us). ``dropped``: the largest of the
    dropped columns' sums where already known (the dropped block is the same at every ``s``:
    ``G_N`` and the normal stiffness do not depend on it, nor do the exact zeros around it,
    so its sums are the same numbers at every evaluation), negative to compute it here.
    ``form``: return the whole ``T(s)`` (for :func:`_track`'s steps one by one); without,
    where the dropped sums are known, only the kept block is formed (:func:`_hill_rows`, the
    same values; :func:`_refine`, which does not use ``T``) and an empty ``T`` returned.
    Returns ``(T, mu, y, status, res, pair, dropped)``, ``status`` 0, 1 (a zero pivot in the
    pair's LU: LAPACK's then runs) or 2 (the held structure is singular at this ``s``),
    ``dropped`` the largest of the dropped columns' sums: the one given where it was known
    (or where the whole matrix was taken, which needs none), else computed from this ``T``."""
    G = _gain_at(Gc, node, start, length, rows, P, z)
    Zr, ok = _condensed_at(Kf, Mf, Cf, Df, m, harmonics, omega, sigma)
    if not ok:
        return np.zeros((1, 1), dtype=np.complex128), 0j, v, 2, 0.0, 0.0, dropped
    n = m * Zr.shape[0]
    nk = keep.size
    at = np.full(n, -1, dtype=np.int64)  # each unknown's place among the kept ones
    for i in range(nk):
        at[keep[i]] = i
    whole = nk == n
    for j in range(n):  # a start with a part on the dropped unknowns: the whole matrix
        if at[j] < 0 and v[j] != 0:
            whole = True
            break
    if whole:
        T = _hill_matrix(G, Zr, eps)
        mu, y, ok = _pair_small(T, v, mu0, steps)
        if not ok:
            return T, 0j, v, 1, 0.0, 0.0, dropped
        res, pair = _residuals(T, y, mu, 0.0)
        return T, mu, y, 0, res, pair, dropped
    if form or dropped < 0.0:
        T = _hill_matrix(G, Zr, eps)
        if dropped < 0.0:  # the dropped columns' sums, as the whole matrix's 1-norm takes them
            dropped = 0.0
            for j in range(n):
                if at[j] >= 0:
                    continue
                col = 0.0
                for i in range(n):
                    col += abs(T[i, j])
                dropped = max(dropped, col)
        Tk = np.empty((nk, nk), dtype=np.complex128)
        for i in range(nk):
            for j in range(nk):
                Tk[i, j] = T[keep[i], keep[j]]
    else:
        T = np.zeros((0, 0), dtype=np.complex128)
        Tk = _hill_rows(G, Zr, eps, at, nk)
    vk = np.empty(nk, dtype=np.complex128)
    for i in range(nk):
        vk[i] = v[keep[i]]
    mu, yk, ok = _pair_small(Tk, vk, mu0, steps)
    if not ok:
        return T, 0j, v, 1, 0.0, 0.0, dropped
    res, pair = _residuals(Tk, yk, mu, dropped)
    y = np.zeros(n, dtype=np.complex128)
    for i in range(nk):
        y[keep[i]] = yk[i]
    return T, mu, y, 0, res, pair, dropped


def _decoupled_normals(mg, structure, H: int, eps: float):
    """``keep`` for :func:`_evaluate`: where every node's normal coordinate is
    decoupled (a prescribed normal force on a coordinate of its own: in the structure's
    matrices its row and column zero off the diagonal, no mass nor damping on it, a stiffness
    ``k``; in ``G`` no coupling between its block ``G_N`` and the tangential one, the split's
    rows none either), ``T(s)`` is block-diagonal with ``eps I - (eps - k) G_N`` on those
    unknowns, the same at every ``s`` (the split touches tangential rows only): no exponent
    there where that block is well conditioned (2-norm condition number below 1e8), and the
    eigenpair that vanishes lives on the others (a start without a normal part stays without
    one): the tangential unknowns (DOF-major, ``H`` per DOF); all unknowns where any node's
    normal is not decoupled. The tests and the blocks in one compiled call
    (:func:`_normal_blocks`, which also settles the condition of a block near a multiple of
    the identity); the singular values by LAPACK only for a block it leaves open."""
    Kf, Mf, Cf, Df = structure
    nc, dH, _ = mg.constant.shape
    every = np.arange(nc * dH, dtype=np.int64)
    if dH != 2 * H:
        return every
    blocks = np.empty((nc, H, H))
    verdict = _normal_blocks(mg.constant, mg.node, mg.rows, Kf, Mf, Cf, Df, H, float(eps),
                             blocks)
    if verdict == 0:
        return every
    if verdict == 2:  # a block the bound leaves open: the condition numbers as np.linalg.cond
        for p in range(nc):  # has them (the bound's are below)
            sv = np.linalg.svd(blocks[p], compute_uv=False)
            if not (sv[-1] > 0 and sv[0] / sv[-1] < 1e8):  # (a zero: infinite)
                return every
    keep = np.empty(nc * H, dtype=np.int64)
    for p in range(nc):
        keep[p * H:(p + 1) * H] = np.arange((2 * p + 1) * H, (2 * p + 2) * H)
    return keep


#: :func:`_normal_blocks` settles a block ``c I + E`` as well conditioned where
#: ``(|c| + |E|_F) / (|c| - |E|_F)`` is below this: its condition number is at most that
#: (Weyl: every singular value within ``|E|_2 <= |E|_F`` of ``|c|``), ten times below the
#: threshold of 1e8, far above the rounding of the bound's few sums
NORMAL_COND_BOUND = 1e7


@njit(cache=True)
def _normal_blocks(Gc, node, rows, Kf, Mf, Cf, Df, H, eps, blocks):
    """:func:`_decoupled_normals`' tests on plain arrays, the normal blocks
    ``eps I - (eps - k) G_N`` written into ``blocks`` (nc, H, H): 0 where a node's normal is
    coupled (its rows of ``G_c`` or of a stick interval's ``r_I`` meet the other block, or
    the structure's row or column of that coordinate has an entry off the diagonal, or it
    has a mass or a damping), 1 where every node's is decoupled and its block well
    conditioned by the bound of :data:`NORMAL_COND_BOUND` (the block written ``c I + E``,
    ``c`` its mean diagonal entry), 2 where decoupled but a block's condition is left to its
    singular values."""
    nc, dH, _ = Gc.shape
    ns = Kf.shape[0]
    verdict = 1
    for p in range(nc):
        for i in range(H):
            for j in range(H, dH):
                if Gc[p, i, j] != 0.0 or Gc[p, j, i] != 0.0:
                    return 0
        for t in range(node.size):
            if node[t] == p:
                for j in range(H):
                    if rows[t, j] != 0.0:
                        return 0
        a = 2 * p
        for j in range(ns):
            if j != a and (Kf[a, j] != 0.0 or Kf[j, a] != 0.0 or Mf[a, j] != 0.0
                           or Mf[j, a] != 0.0 or Cf[a, j] != 0.0 or Cf[j, a] != 0.0
                           or Df[a, j] != 0.0 or Df[j, a] != 0.0):
                return 0
        if Mf[a, a] != 0.0 or Cf[a, a] != 0.0 or Df[a, a] != 0.0:
            return 0
        f = eps - Kf[a, a]
        c = 0.0
        for i in range(H):
            for j in range(H):
                blocks[p, i, j] = (eps if i == j else 0.0) - f * Gc[p, i, j]
            c += blocks[p, i, i]
        c /= H
        e2 = 0.0
        for i in range(H):
            for j in range(H):
                x = blocks[p, i, j] - (c if i == j else 0.0)
                e2 += x * x
        e = np.sqrt(e2)
        if not (e < abs(c) and abs(c) + e < NORMAL_COND_BOUND * (abs(c) - e)):
            verdict = 2
    return verdict


@njit(cache=True)
def _refine(Gc, node, start, length, rows, P, Kf, Mf, Cf, Df, m, harmonics, omega, eps, N,
            s0, sigma, v, slope, tol, max_iter, floor, keep, dropped):
    """:func:`_track` from a neighbour's start (``sigma``, ``v``, ``slope`` nonzero; no
    deflation) in one compiled call, each step one :func:`_evaluate`: the secant method on
    the eigenvalue ``mu`` of ``T(sigma)`` that continues ``v``, the same steps and stopping
    rule (``|mu| / |T|`` below ``tol``; the iterates kept within 0.5 of the candidate ``s0``
    and above ``2 pi Re sigma = floor``, the logarithm of :data:`NEGLIGIBLE`). Returns
    ``(sigma, v, res, converged, slope, evaluations, status, dropped)``, ``status`` 0, or
    1 / 2 as :func:`_evaluate`'s (then :func:`_track` runs the steps one by one, which take
    LAPACK's pair or raise). ``keep``, ``dropped``: :func:`_evaluate`'s (the latter as the
    first step computed it, for the next refinement)."""
    res = np.inf
    real = s0.imag == 0.0
    mu0 = 0j
    have_prev = False
    sp = 0j
    fp = 0j
    count = 0
    for _ in range(max_iter):
        if abs(sigma - s0) > 0.5 or 2.0 * np.pi * sigma.real < floor:
            break
        z = 1.0 + 0j if sigma == 0 else np.exp(-2.0 * np.pi * sigma / N)
        T, mu, y, status, res, pair, dropped = _evaluate(Gc, node, start, length, rows, P, z,
                                                         Kf, Mf, Cf, Df, m, harmonics, omega,
                                                         sigma, eps, v, mu0, 2, keep, dropped,
                                                         False)
        count += 1
        if status != 0:
            return sigma, v, res, False, slope, count, status, dropped
        v = y
        if res <= tol:
            return sigma, v, res, True, slope, count, 0, dropped
        f = mu
        if have_prev:
            slope = (f - fp) / (sigma - sp) if f != fp else 0j
        new = sigma - f / slope if slope != 0 else sigma
        sp, fp, have_prev = sigma, f, True
        mu0 = 0j if pair < 1e-3 else mu
        if real:
            new = complex(new.real, 0.0)
        if not (np.isfinite(new.real) and np.isfinite(new.imag)) or new == sigma:
            break
        sigma = new
    return sigma, v, res, res <= tol, slope, count, 0, dropped


@njit(cache=True)
def _ruhe(B0, B1, B2, sigma, y, max_iter, split, reuse, norms):
    """:func:`_inverse_iteration` compiled: ``(sigma, y, converged)``. Each Ruhe step
    factors ``P(sigma)`` by the harmonic split (:func:`~fretwear.hb.hill_tracking.
    _split_factor`: the LU of the core's Schur complement, where ``split`` has local
    unknowns or a core; a group near singular joins the core, and where the split refuses
    the step is solved as without one) or by :func:`_lu_small` (not converged at a zero
    pivot), and ends the iteration by :func:`_settled`. After a Ruhe step that lands within
    :data:`KEPT_FROM` of the eigenvalue (:func:`_may_reuse`), the next steps are made on its
    LU (:func:`_kept_step`, up to ``reuse`` of them; 0: Ruhe's steps only), each first
    measuring the current pair's backward error (:func:`_residual_into`, Tisseur's with
    ``norms``, :func:`_column_norms`): the iteration ends with the pair where that is at or
    below :data:`COPY_EXACT` (an exact eigenpair of a pencil that near ``P``), and goes back
    to a new LU where a step on the kept one does not contract by :data:`KEPT_CONTRACTION`.
    Every step counts in ``max_iter``."""
    n = B0.shape[0]
    x = _unit(y)
    first = True
    A = np.empty((n, n), dtype=np.complex128)
    vecs = np.empty((4, n), dtype=np.complex128)  # B0 x, B1 x, B2 x, a right side
    T = _transposes(B0, B1, B2)
    piv = np.arange(n)
    use = split[0].size + split[2].size > 0
    work = split_work(split, n)
    last = np.inf
    count = 0  # the steps taken, on a new LU or a kept one
    while count < max_iter:
        count += 1
        _pencil_into(B0, B1, B2, sigma, A)
        how = 0
        while use:  # a group near singular at sigma joins the core (kept for the next steps)
            piv, bad = _split_factor(A, split, work)
            if bad == -1:
                how = 2
                break
            if bad == -2 or 2 * split[2].size > n:
                use = False
                break
            split = _demote(split, bad)
            work = split_work(split, n)
        if how == 0:
            piv, ok = _lu_small(A)
            if not ok:
                return sigma, x, False
        if first:  # towards the eigenvector of the eigenvalue nearest sigma
            x = _unit(_solve_pencil(A, piv, x, how, split, work))
            first = False
        _products_into(T[0], T[1], T[2], x, vecs)
        _slope_from(vecs, sigma)
        prev = last
        sigma, x, state, last = _ruhe_update(sigma, x, _solve_pencil(A, piv, vecs[3], how,
                                                                      split, work), last)
        if state != 0:
            return sigma, x, state > 0
        if reuse == 0 or not _may_reuse(last, prev, max(1.0, abs(sigma))):
            continue
        t, before = last, prev  # the last step and the one before it
        taken = 0
        while True:  # on this LU: the pair's certificate, then a step
            eta = _residual_into(T, sigma, x, vecs, norms)
            if eta <= COPY_EXACT and _kept_settled(t, before, max(1.0, abs(sigma))):
                return sigma, x, True
            if taken >= reuse or count >= max_iter:
                break
            s3, x3, t3 = _kept_step(A, piv, how, split, work, sigma, x, vecs)
            if not 0 <= t3 <= KEPT_CONTRACTION * t:
                break
            sigma, x, t, before = s3, x3, t3, t
            count += 1
            taken += 1
        last = np.inf  # the next LU's step has no contraction to judge
    return sigma, x, False


@njit(cache=True)
def _ruhe_lapack(B0, B1, B2, sigma, y, max_iter):
    """Ruhe's steps (:func:`_ruhe` without the split and the kept LU) with LAPACK's
    ``zgesv`` (``np.linalg.solve``: one LU a solve, two at the first step), for the blocks
    above :data:`PAIR_COMPILED_MAX` unknowns that have no harmonic split; raises
    ``LinAlgError`` at a singular ``P(s)``. A kernel of its own: LAPACK's solve costs
    about 5 s of compilation, which the usual blocks do not need."""
    n = B0.shape[0]
    x = _unit(y)
    A = np.empty((n, n), dtype=np.complex128)
    vecs = np.empty((4, n), dtype=np.complex128)
    T = _transposes(B0, B1, B2)
    last = np.inf
    for count in range(max_iter):
        _pencil_into(B0, B1, B2, sigma, A)
        if count == 0:
            x = _unit(np.linalg.solve(A, x))
        _products_into(T[0], T[1], T[2], x, vecs)
        _slope_from(vecs, sigma)
        sigma, x, state, last = _ruhe_update(sigma, x, np.linalg.solve(A, vecs[3]), last)
        if state != 0:
            return sigma, x, state > 0
    return sigma, x, False


@njit(cache=True)
def _may_reuse(size, last, scale):
    """Whether the LU of Ruhe's last step (at ``tau``, a step of ``size`` from the new
    ``sigma``, after one of ``last``) is kept for the next steps (:func:`_kept_step`):
    ``size`` (about ``|tau - lambda|``) within :data:`KEPT_FROM` of ``scale`` and, after a
    step before it, contracted to 1e-2 of it (the quadratic regime; a first step has none to
    judge: its size alone). A step on the kept LU contracts the error by about ``|tau -
    lambda|`` over the gap to the next eigenvalue; where it does not, :func:`_ruhe` makes a
    new LU, and the pair it returns is certified by its backward error whatever the LU."""
    if size > KEPT_FROM * scale:
        return False
    return not last < np.inf or size <= 1e-2 * last


@njit(cache=True)
def _kept_settled(t, before, scale):
    """Whether the pair after a step of ``t`` (after one of ``before``), its backward error
    at rounding, ends :func:`_ruhe`: ``t`` below 1e-14 of ``scale``, or the error after it
    predicted below 1e-15 of it, ``t^2 / before`` (the step's contraction ``t / before``
    once more: the linear rate of :func:`_kept_step`, above the quadratic one of Ruhe's
    step). After a first step (``before`` infinite) only the first test."""
    if t <= 1e-14 * scale:
        return True
    return before < np.inf and t * t <= 1e-15 * scale * before


@njit(cache=True)
def _products_into(T0, T1, T2, x, vecs):
    """``vecs[j] = B_j x`` for ``j = 0, 1, 2`` (``vecs`` (4, n)) from the transposes ``T_j =
    B_j^T`` (C-ordered, :func:`_transposes`): column by column (``sum_j B[i, j] x[j]`` in
    the order of ``j``, the row products' sums), the real and imaginary parts of ``x``
    apart, so that a real matrix takes two real products an entry and the loop over ``i``
    runs over contiguous entries without a reduction (it vectorises: 3.3 against 5.2-6.2 us
    for the row sums at 62 unknowns)."""
    n = x.size
    acc = np.zeros((6, n), dtype=T0.dtype)  # the matrices' type (real or complex)
    for j in range(n):
        xr = x[j].real
        xi = x[j].imag
        for i in range(n):
            acc[0, i] += T0[j, i] * xr
            acc[1, i] += T0[j, i] * xi
            acc[2, i] += T1[j, i] * xr
            acc[3, i] += T1[j, i] * xi
            acc[4, i] += T2[j, i] * xr
            acc[5, i] += T2[j, i] * xi
    for i in range(n):
        vecs[0, i] = acc[0, i] + 1j * acc[1, i]
        vecs[1, i] = acc[2, i] + 1j * acc[3, i]
        vecs[2, i] = acc[4, i] + 1j * acc[5, i]


@njit(cache=True)
def _transposes(B0, B1, B2):
    """``B_j^T`` C-ordered, for :func:`_products_into`."""
    return (np.ascontiguousarray(B0.T), np.ascontiguousarray(B1.T),
            np.ascontiguousarray(B2.T))


@njit(cache=True)
def _slope_from(vecs, sigma):
    """``vecs[3] = P'(sigma) x = B1 x + 2 sigma B2 x`` from :func:`_products_into`'s."""
    two = 2.0 * sigma
    for i in range(vecs.shape[1]):
        vecs[3, i] = vecs[1, i] + two * vecs[2, i]


@njit(cache=True)
def _residual_into(T, sigma, x, vecs, norms):
    """The products ``B_j x`` (:func:`_products_into` of the transposes ``T``), ``vecs[3] =
    P(sigma) x`` and the backward error of ``(sigma, x)`` (:func:`_backward_error`'s, the
    residual summed from the three products instead of the matrix's entries: the same to
    rounding)."""
    _products_into(T[0], T[1], T[2], x, vecs)
    s2 = sigma * sigma
    res = 0.0
    nv = 0.0
    for i in range(x.size):
        r = vecs[0, i] + sigma * vecs[1, i] + s2 * vecs[2, i]
        vecs[3, i] = r
        res += r.real * r.real + r.imag * r.imag
        nv += x[i].real * x[i].real + x[i].imag * x[i].imag
    den = (norms[0] + abs(sigma) * norms[1] + abs(sigma) ** 2 * norms[2]) * np.sqrt(nv)
    return np.sqrt(res) / den if den > 0 else np.inf


@njit(cache=True)
def _kept_step(A, piv, how, split, work, sigma, x, vecs):
    """A step of the residual inverse iteration (Neumaier, SIAM J. Numer. Anal. 22, 1985)
    at ``sigma`` with the factors of ``P(tau)`` of a step before (``A``, ``piv``, ``work``
    as :func:`_solve_pencil` takes them, ``how`` 0 or 2) and ``vecs`` of
    :func:`_residual_into` (``B_j x`` and ``P(sigma) x``): with ``u0 = P(tau)^-1 P(sigma)
    x`` and ``u1 = P(tau)^-1 P'(sigma) x``, the eigenvalue ``sigma' = sigma - (x^H u0) /
    (x^H u1)`` (with ``tau = sigma`` Ruhe's step itself; near the simple eigenvalue
    ``lambda``, ``P(tau)^-1 = x1 w1^H / mu(tau) + R`` with ``mu(tau)`` about ``(tau -
    lambda) w1^H P' x1``: the two-sided Newton correction ``w1^H P(sigma) x / w1^H P'(sigma)
    x``, ``w1`` the left eigenvector, up to terms of order ``|tau - lambda|`` times the
    vector's error) and the vector ``x - P(tau)^-1 P(sigma') x`` normalised, with
    ``P(sigma') x`` to first order in ``sigma' - sigma`` (``u0 + (sigma' - sigma) u1``;
    the term left out is of the step's square). Its fixed point is an eigenpair of ``P``
    itself, whatever ``tau`` (the inverse iteration ``P(tau)^-1 P'(sigma) x`` stops short of
    the eigenvector by about ``|tau - lambda|^2``), and the error contracts by about
    ``|tau - lambda|`` over the gap to the next eigenvalue. Two solves and the products
    instead of an LU. Returns ``(sigma', x', size)``, ``size = |sigma' - sigma|``, -1 where
    the denominator is zero or not finite (``sigma``, ``x`` unchanged)."""
    n = x.size
    u0 = _solve_pencil(A, piv, vecs[3], how, split, work)
    _slope_from(vecs, sigma)
    u1 = _solve_pencil(A, piv, vecs[3], how, split, work)
    num = 0j
    den = 0j
    for i in range(n):
        num += np.conj(x[i]) * u0[i]
        den += np.conj(x[i]) * u1[i]
    if (not np.isfinite(den.real) or not np.isfinite(den.imag) or den == 0
            or not np.isfinite(num.real) or not np.isfinite(num.imag)):
        return sigma, x, -1.0
    step = num / den
    v = np.empty(n, dtype=np.complex128)
    for i in range(n):
        v[i] = x[i] - (u0[i] - step * u1[i])
    return sigma - step, _unit(v), abs(step)


@njit(cache=True)
def _solve_pencil(A, piv, b, how, split, work):
    """``A^-1 b``: from ``A``'s LU in place (``how`` 0, :func:`_lu_small`) or by the
    harmonic split's factors (2, :func:`~fretwear.hb.hill_tracking._split_solve`; ``A``
    unchanged)."""
    if how == 2:
        return _split_solve(A, split, work, piv, b)
    return _lu_solve_small(A, piv, b)


@njit(cache=True)
def _pencil_into(B0, B1, B2, sigma, A):
    """``A = P(sigma) = B0 + sigma B1 + sigma^2 B2`` (in place)."""
    n = B0.shape[0]
    s2 = sigma * sigma
    for i in range(n):
        for j in range(n):
            A[i, j] = B0[i, j] + sigma * B1[i, j] + s2 * B2[i, j]


@njit(cache=True)
def _ruhe_update(sigma, x, u, last):
    """Ruhe's step from ``u = P(sigma)^-1 P'(sigma) x``: ``sigma - 1 / (x^H u)`` and the
    normalised ``u``, with ``state`` 1 (converged, :func:`_settled`; ``last`` the previous
    step's size), -1 (``x^H u`` zero or not finite: failed, ``sigma`` and ``x`` unchanged) or
    0 (go on), and this step's size."""
    den = 0j
    for i in range(x.shape[0]):
        den += np.conj(x[i]) * u[i]
    if not np.isfinite(den.real) or not np.isfinite(den.imag) or den == 0:
        return sigma, x, -1, last
    step = 1.0 / den
    sigma = sigma - step
    x = _unit(u)
    if _settled(abs(step), last, max(1.0, abs(sigma))):
        return sigma, x, 1, abs(step)
    return sigma, x, 0, abs(step)


@njit(cache=True)
def _settled(size, last, scale):
    """Whether Ruhe's iteration has converged after a step of ``size`` (``last`` the one
    before, ``scale = max(1, |sigma|)``): the step below 1e-14 of ``scale``, or below 1e-7
    of it and the next one predicted below 1e-15 of it. Near a simple eigenvalue the error
    after a step is ``C size^2`` (quadratic convergence), ``C`` estimated by
    ``size / last^2``; the prediction is trusted where the step contracted by 1e3 at least
    (the quadratic regime), and then the step that would confirm it (one LU) is not taken:
    the eigenvalue is within the prediction of the one that step would give, and the vector,
    from a solve at ``sigma`` already ``size`` from the eigenvalue, as accurate. A first
    step (``last`` infinite) has no contraction to judge: only the 1e-14 test ends it."""
    if size <= 1e-14 * scale:
        return True
    if size > 1e-7 * scale or not last < np.inf or size > 1e-3 * last:
        return False
    return size * size * (size / (last * last)) <= 1e-15 * scale


def _pair(T: np.ndarray, v: np.ndarray, mu0: complex, steps: int = 2):
    """The eigenpair ``(mu, y)`` of ``T`` nearest ``mu0`` that continues ``v``: inverse
    iteration from ``v`` with the shift ``mu0`` (one LU of ``T - mu0 I``, ``steps`` solves),
    ``mu`` the Rayleigh quotient of ``y``; also the LU (for the left vector; None when it
    ran compiled, :func:`_pair_small`, up to :data:`PAIR_COMPILED_MAX` unknowns: made again
    where needed). From a start close to the eigenvector (the previous iterate of
    :func:`_track`) each solve reduces its error by ``|mu - mu0| / |mu' - mu0|`` over the
    next eigenvalue ``mu'``: the pair tracked stays the one started, as a full
    eigendecomposition with the largest overlap picks it, at the cost of one LU instead of a
    dense nonsymmetric eigensolve."""
    if T.shape[0] <= PAIR_COMPILED_MAX:
        mu, y, ok = _pair_small(np.ascontiguousarray(T, dtype=complex),
                                np.ascontiguousarray(v, dtype=complex), complex(mu0), steps)
        if ok:
            return complex(mu), y, None
    return _pair_lapack(T, v, mu0, steps)


def _pair_lapack(T: np.ndarray, v: np.ndarray, mu0: complex, steps: int = 2):
    """:func:`_pair` by LAPACK's LU (``zgetrf``), which it returns."""
    A = np.array(T, dtype=complex)
    if mu0 != 0:
        A[np.diag_indices(A.shape[0])] -= mu0
    lu = zgetrf(A, overwrite_a=True)[:2]
    y = v / np.linalg.norm(v)
    for _ in range(steps):
        y = zgetrs(*lu, y)[0]
        y = y / np.linalg.norm(y)
    mu = complex(np.vdot(y, T @ y))
    return mu, y, lu


def _track(hp: HillProblem, sigma: complex, v: np.ndarray, opt: HillOptions,
           warm: Refined | None = None, deflate: float | None = None):
    """The exponent of the exact ``T`` continued from ``sigma`` with eigenvector ``v``: the
    scalar equation ``mu(sigma) = 0`` for the eigenvalue ``mu`` of the linear problem
    ``T(sigma) y = mu y`` whose eigenvector continues ``v`` (:func:`_pair`: inverse iteration
    from the previous eigenvector, shifted by the previous eigenvalue), solved by the secant
    method. Following an eigenvector of ``T(sigma)`` rather than Newton's method on
    ``T(sigma) v = 0`` keeps to the member of the family that was started (centred): the
    truncated problem has copies of every exponent one harmonic apart, and Newton's iterate
    drifts to a near copy whose eigenvector its normalisation does not see. ``warm``: the
    start ``(sigma, v)`` and the first step's slope instead of the candidate's and a forward
    difference (:func:`_warm_start`); the neighbourhood of the candidate ``sigma`` that the
    iterates must not leave, and the stopping rule, are the same. Returns ``(sigma, v,
    residual, converged, slope)``; the residual is ``|mu| / |T|`` (with ``|T v - mu v| / |T|``
    below the same tolerance: an eigenpair), ``slope`` the last ``d mu / d sigma`` used.
    ``deflate``: a real root already found, the equation ``mu(sigma) / (sigma - deflate) = 0``
    instead (another crossing of the same eigenvalue branch, :func:`_landed_real`; not
    converged back on ``deflate``, within :data:`ON_REAL`)."""
    if warm is not None and deflate is None and hp._fused is not None and warm.slope != 0:
        out = _refine(*hp._fused, *hp._structure, hp.prob.m, hp.harmonics, hp.omega,
                      float(hp.prob.eps), float(hp.N), complex(sigma), complex(warm.sigma),
                      np.ascontiguousarray(warm.v, dtype=complex), complex(warm.slope),
                      float(opt.newton_tol), int(opt.newton_max_iter),
                      LOG_NEGLIGIBLE, hp._keep, hp._dropped)
        hp.evaluations += out[5]  # (made, whether or not the steps are then taken again)
        hp._dropped = out[7]
        if out[6] == 0:  # (else: the steps one by one, which take LAPACK's pair or raise)
            s1, v1, r1, conv, slope1 = out[:5]
            return complex(s1), v1, float(r1), bool(conv), complex(slope1)
    prev = None
    res = np.inf
    start = sigma
    slope = 0.0
    if warm is not None:
        sigma, v, slope = warm.sigma, warm.v, warm.slope
    real = start.imag == 0.0  # a real exponent of the real problem stays real (until it
    # meets another one, which the frozen-memory candidates would show as a pair)
    mu0 = 0.0
    for _ in range(opt.newton_max_iter):
        if abs(sigma - start) > 0.5 or 2.0 * np.pi * sigma.real < LOG_NEGLIGIBLE or (
                deflate is not None and abs(sigma - deflate) <= ON_REAL):
            break  # left the neighbourhood of the candidate (or back on the root deflated)
        T, mu, v, lu, res, pair = hp.evaluate(sigma, v, mu0)
        if res <= opt.newton_tol:
            return sigma, v, res, True, slope
        f = mu if deflate is None else mu / (sigma - deflate)
        if prev is None:  # first step: the neighbour's slope, or a forward difference
            if slope == 0:
                if lu is None:  # the compiled pair's: LAPACK's for the left vector
                    lu = _pair_lapack(T, v, mu0, 0)[2]
                slope = _mu_derivative(hp, sigma, v, T, lu, opt.step)
                if deflate is not None:  # d/ds of mu / (s - s1)
                    slope = (slope * (sigma - deflate) - mu) / (sigma - deflate) ** 2
        else:
            s0, f0 = prev
            slope = (f - f0) / (sigma - s0) if f != f0 else 0.0
        new = sigma - f / slope if slope != 0 else sigma
        prev = (sigma, f)
        mu0 = 0.0 if pair < 1e-3 else mu  # near the root, the eigenvalue nearest 0
        if real:
            new = complex(new.real, 0.0)
        if not np.isfinite(new) or new == sigma:
            break
        sigma = complex(new)
    return sigma, v, res, res <= opt.newton_tol, slope


#: a refined exponent from a complex candidate whose imaginary part is below this [w] and
#: a thousandth of the candidate's landed on the real axis: a real exponent (a multiplier's
#: phase of 2 pi 1e-6 per period is no oscillation)
ON_REAL = 1e-6


def _landed_real(s0: complex, s1: complex) -> bool:
    """The refinement of the complex candidate ``s0`` converged to the real ``s1``: the
    frozen-memory pair split on the real axis in the exact problem (a pair of real
    multipliers, one of which is the other member of the pair)."""
    return s0.imag != 0.0 and abs(s1.imag) <= min(ON_REAL, 1e-3 * abs(s0.imag))


def _warm_start(track: HillTrack | None, j: int | None, s0: complex) -> Refined | None:
    """Where the refinement of candidate ``s0`` starts along a sweep: the neighbour's
    refinement of the same candidate (member ``j`` of its :class:`HillTrack`, which
    :func:`track_eigen` continued to ``s0``) moved by as much as the candidate moved, with its
    eigenvector and its last secant slope; None (start from the candidate, the slope by a
    forward difference) where the neighbour did not refine it or the candidates were not
    tracked. The refinement stops by the same rule from either start and keeps to the
    candidate's neighbourhood, so it converges to the same exponent (to ``newton_tol``), in
    fewer evaluations of ``T(s)``: the start is a neighbour's root, and no forward
    difference is taken."""
    if track is None or j is None or track.refined is None:
        return None
    r = track.refined[j]
    if r is None or abs(s0 - r.candidate) > 0.25:  # (a candidate whose centre moved to the
        return None  # next copy: the neighbour's eigenvector is another copy's)
    moved = r.sigma + (s0 - r.candidate)
    if s0.imag == 0.0:  # a real exponent stays on the real axis (:func:`_track`)
        moved = complex(moved.real, 0.0)
    return Refined(r.candidate, moved, r.v, r.slope)


def _mu_derivative(hp: HillProblem, sigma: complex, v: np.ndarray, T: np.ndarray, lu,
                   step: float) -> complex:
    """``d mu / d sigma = w^H T' v / w^H v`` of a simple eigenvalue with right eigenvector
    ``v`` (left eigenvector ``w`` of ``T`` by inverse iteration on ``T^H`` with the LU of
    :func:`_pair`), ``T'`` by a forward difference."""
    w = zgetrs(*lu, v, trans=2)[0]
    w = zgetrs(*lu, w / np.linalg.norm(w), trans=2)[0]
    dT = (hp.matrix(sigma + step) - T) / step
    den = np.vdot(w, v)
    return complex(np.vdot(w, dT @ v) / den) if den != 0 else 0.0


def _centroid_of(v: np.ndarray, m: int, H: int, k: int) -> float:
    """:func:`centroid` of one refined eigenvector ``v`` (m H,): its kernel called directly
    (the wrapper's reshapes and checks cost as much as the kernel on one vector)."""
    return float(_centroids(np.ascontiguousarray(v, dtype=complex).reshape(1, m, H), k)[0])


def hill_stability(prob: DLFTProblem, U, dyn: StructureDynamics, *,
                   options: HillOptions | None = None,
                   previous: FloquetResult | None = None) -> FloquetResult:
    """Floquet exponents and multipliers of the converged solution ``U`` (m, H) of ``prob``
    by Hill's method (module docstring); ``dyn`` the structure
    (:func:`fretwear.hb.dynamics.structure_dynamics` of the model); ``previous``: the result
    at a neighbouring solution of the same model and basis (the previous point of a sweep),
    whose candidates are continued where that gives the dense eigensolve's
    (:func:`track_eigen`, ``options.track``)."""
    opt = _DEFAULT_OPTIONS if options is None else options
    t0 = time.perf_counter()
    hp = HillProblem(prob, U, dyn)
    det_sign = hp.det_sign()
    m, H, k = prob.m, prob.H, len(prob.basis.harmonics)
    q = hp.candidate_structure[1]  # the interior coordinates of the candidates' pencil
    prev = previous.track if (previous is not None and opt.track) else None
    regime = hp.regime()
    if prev is not None and prev.regime != regime:
        prev = None
    red = reduce_quadratic(*hp.pencil(), hint=prev)
    cut = 2.0 * (k + 1) + 10.0
    got = track_eigen(red, prev, (m + q, H, k), hp.omega)
    origin = None
    if got is not None:  # member j continues member origin[j] of the neighbour's track
        vals, vecs, kap, origin = got
        idx = np.argsort(-vals.real, kind="stable")
        kap, edge = kap[idx], np.zeros(vals.size, dtype=bool)
    else:
        vals, vecs = dense_eigen(red)
        finite = np.flatnonzero(np.isfinite(vals) & (np.abs(vals) < cut))
        kap = np.atleast_1d(centroid(vecs[:, finite].T.reshape(-1, m + q, H), k))
        keep = np.abs(kap) <= 0.5 + 1e-9
        edge = _edge_members(vals[finite], kap, keep)
        keep |= edge
        idx, kap, edge = finite[keep], kap[keep], edge[keep]
        half = vals[idx].imag >= -1e-12 * np.maximum(np.abs(vals[idx]), 1.0)
        idx, kap, edge = idx[half], kap[half], edge[half]
        order = np.argsort(-vals[idx].real, kind="stable")
        idx, kap, edge = idx[order], kap[order], edge[order]
    kept = vals[idx]  # (sorted by decreasing real part)
    track = _track_record(red, kept, vecs[:, idx], kap, edge, H, cut)
    if track is not None:
        track.regime = regime
        track.omega = hp.omega
        if got is not None and prev.omega is not None and hp.omega != prev.omega:
            track.velocity = _velocity(kept, origin[idx], prev.sigma, hp.omega - prev.omega)
    memoryless = hp.memoryless()
    exact = memoryless and dyn.exact and not hp.truncated
    # a law without memory on a truncated pencil: every candidate is an exponent of the whole
    # problem moved by the truncation alone (about 1e-4), so every one is refined, and one
    # whose refinement fails stays a candidate (the truncation, not an artefact)
    budget = idx.size if (memoryless and hp.truncated) else opt.refine
    # a held member of a truncated pencil is exact only where the kept modes diagonalise
    # the interior (proportional or modal damping)
    held_exact = not hp.truncated or dyn.held_diagonal
    sig, kaps, res, kind, spurious = [], [], [], [], []

    def report(s, kp, r, how):
        sig.append(s)
        kaps.append(kp)
        res.append(r)
        kind.append(how)

    refined = 0
    done: list = [None] * idx.size  # the refinements, for the neighbour's warm starts
    for pos, (i, kp, s0) in enumerate(zip(idx.tolist(), kap.tolist(), kept.tolist(),
                                          strict=True)):
        y = vecs[:, i]
        vx = y[:m * H]
        held = np.vdot(vx, vx).real < 1e-16 * np.vdot(y, y).real  # |vx| < 1e-8 |y|
        negligible = 2.0 * np.pi * s0.real < LOG_NEGLIGIBLE
        if held or exact or negligible or refined >= budget:  # refined: successes
            report(s0, kp, np.nan,
                   "held" if held and held_exact else "exact" if exact else "candidate")
            continue
        j = None if origin is None or origin[i] < 0 else int(origin[i])
        warm = _warm_start(prev, j, s0)
        s1, v1, r1, conv, slope = _track(hp, s0, vx, opt, warm)
        if not conv and warm is not None:  # from the candidate, as without a neighbour
            s1, v1, r1, conv, slope = _track(hp, s0, vx, opt)
        refined += conv
        if not conv and memoryless:  # not a frozen-memory artefact: the candidate of a
            report(s0, kp, np.nan, "candidate")  # truncated (or modal) interior, kept
            continue
        if not conv:  # no exponent of the exact problem near it: an artefact of the frozen
            spurious.append(s0)  # memory (a node that sticks part of the period)
            continue
        if _landed_real(s0, s1):  # a pair of real exponents: find the other one, or say
            s1 = complex(s1.real, 0.0)  # that it is missing (the conjugate candidate)
            a = s0.real if abs(s0.real - s1.real) > 10 * ON_REAL else s1.real - 0.01
            s2, v2, r2, conv2, _ = _track(hp, complex(a, 0.0), vx, opt, deflate=s1.real)
            if conv2:
                report(complex(s2.real, 0.0), _centroid_of(v2, m, H, k), r2, "refined")
            else:
                report(np.conj(s0), -kp, np.nan, "candidate")
        done[pos] = Refined(s0, s1, v1, slope)
        report(s1, _centroid_of(v1, m, H, k), r1, "refined")
    if track is not None:
        track.refined = done
    # one multiplier per family (:func:`_families`), sorted by decreasing real part
    allsig, mult, allkap, allres, src = _families(np.array(sig, dtype=complex),
                                                  np.array(kaps, dtype=float),
                                                  np.array(res, dtype=float), EDGE_TOL)
    w = hp.omega
    return FloquetResult(exponents=allsig * w, multipliers=mult, centroid=allkap,
                         residual=allres, kind=np.array(kind, dtype=object)[src],
                         neutral=hp.neutral(), omega=w,
                         spurious=np.array(spurious, dtype=complex) * w,
                         evaluations=hp.evaluations, wall_time=time.perf_counter() - t0,
                         stable_tol=opt.stable_tol, det_sign=det_sign,
                         tracked=got is not None, track=track)


def _velocity(kept: np.ndarray, src: np.ndarray, before: np.ndarray, dw: float) -> np.ndarray:
    """:attr:`HillTrack.velocity`: per member ``kept`` (``s / w``), its motion from the
    neighbour's member ``before[src]`` over the step ``dw`` of ``w`` (times ``1 / dw``), 0
    where it was not continued (``src`` -1) or moved 0.1 or more (another member's start).
    The members are few: a loop on Python's scalars."""
    vel = np.zeros(kept.size, dtype=complex)
    inv = 1.0 / dw
    for pos, (j, s) in enumerate(zip(src.tolist(), kept.tolist(), strict=True)):
        if j >= 0:
            moved = s - complex(before[j])
            if abs(moved) < 0.1:
                vel[pos] = complex(moved.real * inv, moved.imag * inv)
    return vel


@njit(cache=True)
def _families(sig, kap, res, edge_tol):
    """The exponents ``sig`` (``s / w``, one member per family with ``Im s >= 0``), their
    centroids ``kap`` and residuals ``res`` completed and sorted as
    :class:`FloquetResult` holds them, in one compiled call: one multiplier per family (the
    conjugate of a complex exponent is another family, centroid negated, except at
    ``Im s = w/2``, within ``edge_tol``, where ``s`` and its conjugate ``s - i w`` are the two
    members of one family with a real negative multiplier ``-e^{2 pi Re sigma}``: a
    period-doubling direction), ordered by decreasing real part (a stable sort, by insertion:
    the families are few and it compiles in less time than numba's merge sort; the order of
    ``sig`` among equal real parts, each conjugate after the exponents). Returns ``(sigma,
    multipliers, centroid, residual, source)``, ``source`` the index in ``sig`` each came
    from."""
    n = sig.size
    edge = np.empty(n, dtype=np.bool_)
    extra = 0
    for i in range(n):
        edge[i] = abs(abs(sig[i].imag) - 0.5) <= edge_tol
        if abs(sig[i].imag) > 1e-9 * max(abs(sig[i]), 1.0) and not edge[i]:
            extra += 1
    total = n + extra
    src = np.empty(total, dtype=np.int64)
    conj = np.zeros(total, dtype=np.bool_)
    key = np.empty(total)
    j = n
    for i in range(n):
        src[i] = i
        key[i] = -sig[i].real
        if abs(sig[i].imag) > 1e-9 * max(abs(sig[i]), 1.0) and not edge[i]:
            src[j] = i
            conj[j] = True
            key[j] = -sig[i].real
            j += 1
    order = np.arange(total)
    for a in range(1, total):
        o = order[a]
        b = a - 1
        while b >= 0 and key[order[b]] > key[o]:
            order[b + 1] = order[b]
            b -= 1
        order[b + 1] = o
    s = np.empty(total, dtype=np.complex128)
    mult = np.empty(total, dtype=np.complex128)
    k = np.empty(total)
    r = np.empty(total)
    out = np.empty(total, dtype=np.int64)
    for a in range(total):
        i = src[order[a]]
        out[a] = i
        r[a] = res[i]
        if conj[order[a]]:
            s[a] = np.conj(sig[i])
            k[a] = -kap[i]
            mult[a] = np.exp(2.0 * np.pi * s[a])
        elif edge[i]:
            s[a] = sig[i]
            k[a] = kap[i]
            mult[a] = -np.exp(2.0 * np.pi * sig[i].real)
        else:
            s[a] = sig[i]
            k[a] = kap[i]
            mult[a] = np.exp(2.0 * np.pi * sig[i])
    return s, mult, k, r, out


def stability(model: Model, sol: PeriodicSolution, *, options: HillOptions | None = None,
              dyn: StructureDynamics | None = None, condenser=None,
              previous: FloquetResult | None = None) -> FloquetResult:
    """:func:`hill_stability` of a converged :class:`~fretwear.hb.solution.PeriodicSolution`
    of ``model`` (its problem rebuilt from the solution: frequency, basis, gap, eps,
    anchors); ``dyn``: the model's :func:`fretwear.hb.dynamics.structure_dynamics` if already
    made (a sweep makes it once); ``condenser``: the model's condenser, as the solve had it;
    ``previous``: the result at a neighbouring solution (:func:`hill_stability`)."""
    if not sol.success:
        raise InputError(f"stability of a solution that did not converge ({sol.message})")
    prob = problem_of(model, sol, condenser=condenser)
    dyn = structure_dynamics(model, condenser) if dyn is None else dyn
    return hill_stability(prob, sol.U.reshape(prob.m, prob.H), dyn, options=options,
                          previous=previous)


def problem_of(model: Model, sol: PeriodicSolution, *, condenser=None) -> DLFTProblem:
    """The :class:`~fretwear.hb.problem.DLFTProblem` a solution was solved on (``condenser``:
    the model's, None a new exact one)."""
    basis: FourierBasis = sol.basis
    red = condense(model, sol.frequency, basis.orders, quasi_static=sol.quasi_static,
                   condenser=condenser)
    return DLFTProblem(red, model.contact, basis, gap=sol.gap, eps=sol.eps, anchor=sol.anchor)
