"""Quasi-static incremental wear: load steps through each cycle with exact contact and
friction and Archard wear applied as it goes (in the spirit of Stromberg 1997), optionally
with cycle jumps."""

from __future__ import annotations

import math
import time

import numpy as np

from fretwear.errors import ConvergenceError, InputError
from fretwear.hb.reduce import condense_static
from fretwear.model.core import Model
from fretwear.resources import require_memory
from fretwear.timedomain.checks import c_float, check_contact, count, node_wear
from fretwear.timedomain.contact_solve import OPEN, STICK, Contact, ContactState, Settings
from fretwear.timedomain.kernels import LoadCycle, WearRecords, WearState, run_quasistatic
from fretwear.timedomain.options import INCREMENTAL_WEAR, IncrementalWearOptions
from fretwear.timedomain.results import IncrementalWearResult


# --------------------------------------------------------------------------------------------
# quasi-static incremental wear
# --------------------------------------------------------------------------------------------
def incremental_wear(model: Model, *, n_cycles: int = 100,
                     options: IncrementalWearOptions = INCREMENTAL_WEAR,
                     wear_coefficient: float | None = None, wear0=None, progress: bool = False,
                     raise_on_failure: bool = True, condenser=None) -> IncrementalWearResult:
    """Quasi-static fretting wear by load steps (in the spirit of Stromberg 1997).

    At every load step ``tau_k = 2 pi k / steps_per_cycle`` the static equilibrium
    ``K U + T^T lam = F(tau_k)`` is solved with exact Signorini and incremental Coulomb
    friction (the slip is the tangential increment since the previous step), after an exact
    static condensation onto the contact DOFs (``K`` is constant, so each step is a small dense
    contact problem, solved by the same numba kernel as the dynamic solver). After each step,
    every node's wear grows by Archard's law ``dW = k_w * p_N * |delta u_T|``
    (``p_N = lam_N / area``), which opens its gap for the next step. The run starts from the
    unloaded, unworn state (``U = 0``) with one step at ``tau = 0``.

    With ``cycle_jump = J > 1`` the wear of each computed cycle (after the first, which
    includes the initial loading) is counted ``J`` times (explicit Euler on the slow scale):
    ``ceil((n_cycles - 1) / J) + 1`` cycles are computed, the last jump shortened so that the
    total is ``n_cycles``.

    Parameters
    ----------
    model : the structure (inertia and damping are ignored).
    n_cycles : number of load cycles (physical, counting the jumps).
    options : :class:`~fretwear.timedomain.options.IncrementalWearOptions`: load steps per
        cycle ``steps_per_cycle``, cycles represented by each computed cycle ``cycle_jump``,
        ``record_every`` computed cycles a record (and the last), the contact solver's
        relative tolerance ``contact_tol``.
    wear_coefficient : Archard coefficient k_w [1/Pa]; default
        ``model.contact.wear_coefficient`` (plus the partners' coefficient at node-to-node
        pairs: the gap opens by both worn depths).
    wear0 : (nc,) initial wear [m].
    progress : accepted for the analyses' common call (the run prints nothing).
    raise_on_failure : raise :class:`~fretwear.errors.ConvergenceError` when the contact
        problem of some load step does not settle (default); False: return the result with
        ``success`` False and the count in ``message``.
    condenser : the condenser of ``model`` (:func:`fretwear.hb.reduce.exact_condenser`) whose
        static condensation is used (None: a new exact one).

    Returns
    -------
    :class:`IncrementalWearResult`: ``success``, ``message``, and per recorded cycle the
    wear [m], pressure [Pa], slip [m], worn volume [m^3] and dissipation [J].
    """
    if not isinstance(options, IncrementalWearOptions):
        raise InputError(f"options = {options!r}; expected an IncrementalWearOptions(...)")
    N = options.steps_per_cycle
    n_cycles = count(n_cycles, "n_cycles", 1)
    J = options.cycle_jump
    rec_every = options.record_every
    computed = 1 + -(-(n_cycles - 1) // J)  # cycles computed (each stands for up to J)
    if computed * N > MAX_LOAD_STEPS:
        raise InputError(f"an incremental wear run of {computed:,} computed cycles of {N} load "
                         f"steps (n_cycles = {n_cycles:,}, cycle_jump = {J:,}): expected at "
                         f"most {MAX_LOAD_STEPS:,} load steps (days of computing); raise "
                         "cycle_jump or lower n_cycles")
    kw = _archard_coefficient(model, wear_coefficient)
    t0 = time.perf_counter()
    c = model.contact
    nc, d = c.dofs.shape
    area = np.asarray(c.area, dtype=float)
    if area.shape != (nc,) or np.any(area <= 0):
        raise InputError(f"contact.area must be ({nc},) positive areas [m^2]")
    check_contact(model)
    cond = condense_static(model, condenser=condenser)
    A = cond.K
    tau = 2.0 * np.pi * np.arange(N) / N
    Ft = model.load_time(tau) if model.loads else np.zeros((N, model.ndof))
    btab = np.ascontiguousarray(cond.loads(Ft))
    fscale = float(np.abs(btab).max(initial=0.0))
    require_memory(8.0 * computed * (2 + 3 * nc / rec_every),
                   f"an incremental wear run of {computed:,} computed cycles (n_cycles = "
                   f"{n_cycles:,}, cycle_jump = {J:,})")
    jumps = _cycle_jumps(n_cycles, J)
    ncomp = jumps.size
    nrec = sum(1 for i in range(ncomp) if (i + 1) % rec_every == 0 or i == ncomp - 1)
    wear = node_wear(wear0, nc, "wear0")
    gap = np.asarray(c.gap, dtype=float).copy()
    x = np.zeros(nc * d)
    status = np.where(gap <= 0.0, STICK, OPEN).astype(np.int8)
    tdir = np.zeros((nc, d - 1))
    tdir[:, 0] = 1.0
    rec = WearRecords(rec_every, np.zeros((nrec, nc)), np.zeros((nrec, nc)),
                      np.zeros((nrec, nc)), np.zeros(nrec), np.zeros(nrec, dtype=np.int64))
    nr, nfail, maxit = run_quasistatic(
        Contact(A, gap, c_float(c.mu_nodes()), int(d)), LoadCycle(btab, c_float(area), kw, jumps),
        Settings(options.contact_tol, fscale, 60 + 4 * nc),
        WearState(x, wear, ContactState(status, tdir)), rec)
    if nfail and raise_on_failure:
        raise ConvergenceError(f"incremental_wear: {nfail} load steps where the contact solve "
                               "did not settle (singular or cycling); check that the contact "
                               "holds the structure (rigid motions) and the loads")
    message = (f"{n_cycles} cycles ({ncomp} computed, {ncomp * N} load steps)" if not nfail
               else f"{nfail} load steps where the contact solve did not settle")
    lam = np.asarray(A @ (-x) + btab[0]).reshape(nc, d)
    U = cond.recover(x, model.load_time(np.zeros(1))[0] if model.loads
                     else np.zeros(model.ndof))
    return IncrementalWearResult(
        success=not nfail, message=message, cycles=rec.cycle, wear=rec.wear, pressure=rec.press,
        slip=rec.slip,
        worn_volume=rec.wear @ area, dissipation=rec.diss, computed_cycles=ncomp, cycle_jump=J,
        steps_per_cycle=N, k_w=kw, wall_time=time.perf_counter() - t0, U=U, lam=lam,
        info={"max_active_set_iterations": int(maxit), "records": int(nr)})


#: the most load steps (computed cycles x steps per cycle) of one run: at the ~0.1 ms of a
#: load step of a small model, a day of computing
MAX_LOAD_STEPS = 10**9


def _archard_coefficient(model: Model, wear_coefficient) -> float:
    """``wear_coefficient`` k_w [1/Pa] checked, or by default the model's (both surfaces of a
    pair summed: the gap opens by both worn depths), which must be the same at every node."""
    if wear_coefficient is None:
        both = model.contact.wear_nodes() + model.contact.partner_wear_nodes()
        if np.ptp(both) > 0.0:
            raise InputError(f"contact: the Archard coefficients (both surfaces summed) differ "
                             f"between nodes ({sorted(set(both.tolist()))[:4]} 1/Pa); "
                             "incremental_wear takes one coefficient k_w")
        kw = both[0]
    else:
        kw = wear_coefficient
    kw = float(kw)
    if not (math.isfinite(kw) and kw >= 0.0):
        raise InputError(f"wear_coefficient = {wear_coefficient!r}; expected an Archard "
                         "coefficient k_w >= 0 [1/Pa]")
    return kw


def _cycle_jumps(n_cycles: int, J: int) -> np.ndarray:
    """The cycles each computed cycle stands for: 1 (the first, with the initial loading),
    then ``J``, the last shortened so that they add up to ``n_cycles``."""
    rest = n_cycles - 1
    jumps = np.full(1 + -(-rest // J), J, dtype=np.int64)
    jumps[0] = 1
    if rest:
        jumps[-1] = rest - J * (jumps.size - 2)
    return jumps
