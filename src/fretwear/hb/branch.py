"""The continuation state of a sweep: its DLFT problems per frequency, condensed once and kept
within a memory budget (:class:`Problems`), and its converged points with the secant
predictor and the stick anchors of the loading history (:class:`Branch`).

Mean tangential position (stick anchors): the sweep follows the loading history; the first
point starts from the static preload (:func:`fretwear.hb.preload.preload_anchor`) and every
later point takes the mean tangential positions of the previous converged point as its anchors
(a node that sticks all period stays where it was). See docs/theory.md, "Full stick and the
mean position".
"""

from __future__ import annotations

import time

import numpy as np

from fretwear.hb.connectors import connect, springs
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.runs import run
from fretwear.hb.solution import Attempt, assemble_solution
from fretwear.hb.solvers import SolveStats
from fretwear.hb.sweep_result import SweepPoint

#: reduced models a sweep keeps (it revisits the last few frequencies: sub-steps, retries,
#: arclength) at most, and the memory they may take together [bytes]: at 1024 contact nodes
#: and 7 harmonics one reduced model is 1.2 GB, so two are kept there (docs/theory.md,
#: "Large interfaces")
CACHE_SIZE = 8
CACHE_BYTES = 3 * 2**30
#: a converged point keeps the problem it was solved on (:attr:`SweepPoint.problem`, for
#: Hill's method) when its reduced model (``Z`` and the observed DOFs' recovery) takes at most
#: this many bytes: Hill's method then does not condense the model again (0.6-0.9 ms a point
#: on small models). The problem's own arrays (its harmonic blocks, its Jacobian once formed)
#: take a few times that, so 100 points pin some tens of MiB at most; larger models would
#: pin one reduced model per point for the whole sweep
KEEP_PROBLEM_BYTES = 2**16
#: the local basis (:meth:`fretwear.hb.reduce.Condenser.nearby`) serves a frequency where its
#: estimated relative error (``Z_r``, ``F_r``) is at most this: the continuation then takes
#: the exact condensation's steps. At 1e-4 its step lengths differed enough past the bladed
#: disk's fold for the next grid point to land on another of the coexisting friction states
#: (1.4 % at 2800 Hz, a point of the exact condensation all the same); at 1e-6 the shortened
#: FE FRFs take the exact condensation's path, their grid points within 4.4e-9 (bladed disk)
#: and 2.3e-7 (platform damper, after its fold) of the peak amplitude
#: (docs/studies/fallbacks.md, "The condensation along the continuation")
NEARBY_TOL = 1e-6
#: ... and stop serving the sweep once an error measured afterwards by the exact condensation
#: at a frequency they served exceeds this (the estimate was wrong there)
NEARBY_STOP = 1e-2


class Problems:
    """DLFT problems per frequency, condensed once and cached (the sweep revisits them): at
    most ``cache_size`` reduced models and :data:`CACHE_BYTES` of them (the newest always).
    ``eps``: a number [N/m], or ``"auto"`` (the spectral radius of each frequency's ``Z_r``).

    With ``solve`` (the sweep's :class:`~fretwear.hb.options.SolveOptions`) and an exact
    condenser that keeps its interior solutions (``keep_interior``), the frequencies the
    continuation adds (its halved steps, the arclength's correctors and their differences in
    frequency) are condensed by the local basis of the latest exact condensation
    (:meth:`~fretwear.hb.reduce.Condenser.nearby`: no factorisation, no interior solve), and
    where the local bases of the two latest exact condensations agree to :data:`NEARBY_TOL`,
    and every point the sweep records from one of them is polished on the exact condensation
    at its frequency (:meth:`polish`: the solver from that point to the sweep's tolerance),
    so that every recorded point is a converged point of the exact condensation. The
    frequencies of ``exact_at`` (the grid's, [rad/s]) are always condensed exactly. Every
    polish measures the error of the local basis's model it starts from against the exact
    one; above :data:`NEARBY_STOP` the sweep condenses exactly from then on (docs/theory.md,
    "Cost of the condensation"). :attr:`counts`: the condensations made, ``exact`` and
    ``nearby`` (local basis), and the points ``polished`` and ``polish_failed`` (the sweep's
    summary, :attr:`~fretwear.hb.sweep_result.SweepResult.condensations`)."""

    def __init__(self, model, basis, gap, eps, condenser, jacobian="auto", cache_size=CACHE_SIZE,
                 exact_at=(), solve=None):
        self.model, self.basis, self.gap, self.eps = model, basis, gap, eps
        self.jacobian = jacobian
        self.orders = np.array([0, *basis.harmonics])
        self.cache: dict = {}
        self.size = cache_size
        self.last = None  # the last problem handed out
        # the model does not change during a sweep: its condenser (and loads) are read once,
        # the contact springs prepared once, and the problems share their set-up
        self.condenser = condenser
        self.springs = springs(model.contact)
        self.template = None
        self.exact_at = {float(w) for w in exact_at}
        self.solve = solve
        keep = getattr(condenser, "keep_interior", None)
        self.use_nearby = solve is not None and keep is not None and bool(keep())
        self.nearby_keys: set = set()  # cached frequencies served by the local basis
        self.counts = {"exact": 0, "nearby": 0, "polished": 0, "polish_failed": 0}

    def _room(self) -> None:
        """Room for one more reduced model (every frequency's has the size of the cached
        ones): made before the new model is condensed, at 1024 nodes one model less held at
        the peak."""
        size = next(iter(self.cache.values())).Z.nbytes if self.cache else 0
        while self.cache and (len(self.cache) >= self.size or size + sum(
                r.Z.nbytes for r in self.cache.values()) > CACHE_BYTES):
            oldest = next(iter(self.cache))
            self.nearby_keys.discard(oldest)
            self.cache.pop(oldest)

    def _condense(self, omega: float, exact: bool):
        """The reduced model at ``omega`` (springs connected) and whether it is exact (a
        model of the local basis carries its ``estimate``: a point converged on it is
        polished before it is recorded, :meth:`polish`)."""
        red = None
        if not exact and self.use_nearby:
            red = self.condenser.nearby(omega, self.orders, NEARBY_TOL)
        near = red is not None
        if red is None:
            red = self.condenser.reduced(omega, self.orders)
        self.counts["nearby" if near else "exact"] += 1
        if self.springs is not None:
            red = connect(red, self.model.contact, self.springs)
        return red, not near

    def get(self, omega: float, anchor) -> DLFTProblem:
        """The problem at the circular frequency ``omega`` [rad/s] (the continuation
        variable of the sweep) with the stick anchors ``anchor``."""
        key = float(omega)
        red = self.cache.get(key)
        if red is None:
            self._room()
            red, exact = self._condense(omega, key in self.exact_at)
            self.cache[key] = red
            if not exact:
                self.nearby_keys.add(key)
        if self.template is None:
            prob = DLFTProblem(red, self.model.contact, self.basis, gap=self.gap,
                               eps=self.eps, anchor=anchor, jacobian=self.jacobian)
            if self.solve is not None:  # (the operator path's linear algebra)
                prob.krylov = self.solve.krylov
            # the set-up the other frequencies share (DLFTProblem.at), without this
            # frequency's reduced model and blocks: they are not pinned for the whole sweep
            self.template = object.__new__(DLFTProblem)
            self.template.__dict__.update(prob.__dict__)
            self.template.reduced = self.template.blocks = self.template.F = None
        else:
            prob = self.template.at(red, anchor)
        # the GMRES preconditioner of large interfaces (fretwear.hb.krylov) is carried from
        # the neighbouring frequency: GMRES still solves each step to its tolerance, and
        # rebuilds it when it has become slow
        prob._precond = getattr(self.last, "_precond", None)
        self.last = prob
        return prob

    def exact(self, omega: float, anchor) -> DLFTProblem:
        """The problem at ``omega`` [rad/s] on the exact condensation (replacing in the cache
        the local basis's model there)."""
        key = float(omega)
        if key in self.nearby_keys or key not in self.cache:
            self.cache.pop(key, None)
            self.nearby_keys.discard(key)
            self._room()
            self.cache[key], _ = self._condense(omega, True)
        return self.get(omega, anchor)

    def polish(self, omega: float, prob: DLFTProblem, U, stats):
        """``(problem, U, stats)`` of a point converged at ``omega`` [rad/s] on the local
        basis's model (its reduced model's ``estimate`` is not None): the solver from ``U`` on
        the exact condensation there (the sweep's solver, then the other one:
        :func:`~fretwear.hb.runs.run`), its statistics added to ``stats``'s; the local basis's
        error there measured (the worst harmonic's relative error of ``Z_r`` and ``F_r``):
        above :data:`NEARBY_STOP`, the sweep condenses exactly from then on. A point
        converged on an exact model is returned as it is."""
        if prob.reduced.estimate is None:
            return prob, U, stats
        pe = self.exact(omega, prob.anchor)
        near, red = prob.reduced, pe.reduced
        error = max(max(np.linalg.norm(a - b) / max(np.linalg.norm(b), 1e-300)
                        for a, b in zip(x, y, strict=True))
                    for x, y in ((near.Z, red.Z), (near.F, red.F)))
        if error > NEARBY_STOP:
            self.use_nearby = False
        so = self.solve
        for method in (so.solver, so.other_solver):
            x, st = run(pe, U, so.replace(solver=method))
            if st.success:
                break
        self.counts["polished" if st.success else "polish_failed"] += 1
        merged = SolveStats(st.success, st.residual, stats.iterations + st.iterations,
                            stats.nfev + st.nfev, stats.njev + st.njev,
                            stats.wall_time + st.wall_time, st.message, st.solver)
        return pe, x, merged


def rebuild_point(probs: Problems, entry: dict) -> SweepPoint:
    """A sweep point from a checkpoint entry
    (:func:`fretwear.hb.sweep_checkpoint.load_sweep_checkpoint`): its solution re-assembled
    from its harmonics, anchors and penalty by the code that assembled it first, so it equals
    the original bit for bit."""
    rec = entry["record"]
    stats = SolveStats(**rec["stats"])
    sol = None
    if "U" in entry:
        model, basis = probs.model, probs.basis
        prob = DLFTProblem(probs.condenser.reduced(entry["omega"], probs.orders), model.contact,
                           basis, gap=probs.gap, eps=entry["eps"], anchor=entry["anchor"],
                           jacobian=probs.jacobian)
        sol = assemble_solution(prob, np.array(entry["U"], float), model, stats)
    pt = SweepPoint(rec["frequency_hz"], sol, stats, rec["how"], list(rec["flags"]),
                    bool(rec["on_grid"]), rec["time_domain"],
                    [_attempt(a) for a in rec.get("attempts", [])])
    if sol is not None:
        sol.attempts = pt.attempts
    return pt


def _attempt(rec: dict) -> Attempt:
    """An attempt from its checkpoint record. A jump recorded before :class:`Attempt` had
    ``from_hz`` (a checkpoint of an earlier fretwear, of the same format version) gets the
    fold's frequency back from its message, "... (from the fold at <f> Hz)"."""
    a = Attempt(**rec)
    tag = "(from the fold at "
    if a.method == "jump" and a.from_hz is None and tag in a.message:
        try:
            a.from_hz = float(a.message.rsplit(tag, 1)[1].split(" Hz", 1)[0])
        except ValueError:
            pass  # not a number: the summary says "a fold"
    return a


class Branch:
    """The converged points of a sweep so far, in the order computed: the secant predictor in
    frequency, the stick anchors of the loading history, and the recording of points.

    Parameters
    ----------
    model : the structure; anchor : (nc, d-1) stick anchors of the first point [m] (the
    static preload state unless given); flag : ``(PeriodicSolution) -> list[str]``, reasons
    for caution about each converged point (None: none); probs : the sweep's
    :class:`Problems`, whose :meth:`Problems.polish` every recorded point goes through (None:
    points are recorded as given).
    """

    def __init__(self, model, anchor, flag=None, probs=None):
        self.model, self.first_anchor, self.flag = model, anchor, flag
        self.probs = probs
        self._clock = (time.perf_counter(), time.process_time())
        self.history: list = []  # converged (omega, U (m, H)) in order
        self.last_solution = None  # the last converged solution (a time start's neighbour)
        self.points: list = []  # every point computed, intermediate ones included

    def predict(self, omega: float):
        """Start at ``omega`` [rad/s]: the secant through the last two converged points (the
        last one alone, None before any)."""
        if not self.history:
            return None
        if len(self.history) == 1:
            return self.history[-1][1]
        (w0, U0), (w1, U1) = self.history[-2], self.history[-1]
        if w1 == w0:
            return U1
        return U1 + (U1 - U0) * (omega - w1) / (w1 - w0)

    def anchor(self, index: int = -1):
        """Stick anchors of the next point: the mean tangential positions of the converged
        point ``index`` of the history (the last by default; the first point's before
        any)."""
        if not self.history:
            return self.first_anchor
        c = self.model.contact
        U = self.history[index][1].reshape(c.n_nodes, c.dim, -1)
        return U[:, 1:, 0].copy()

    def lap(self) -> tuple[float, float]:
        """Wall and CPU seconds since the last lap (the branch's creation before any); the
        clock restarts. Every recorded point takes its lap (:attr:`SweepPoint.seconds`), so a
        grid point's and its intermediate points' laps add up to what the sweep spent on
        it from the lap that started it."""
        now = (time.perf_counter(), time.process_time())
        wall, cpu = now[0] - self._clock[0], now[1] - self._clock[1]
        self._clock = now
        return wall, cpu

    def record(self, omega, prob, U, stats, how) -> SweepPoint:
        """The converged point ``U`` (m, H) at ``omega`` [rad/s] of ``prob``, added to the
        history (not to :attr:`points`); converged on the local basis's model, polished on
        the exact condensation first (:meth:`Problems.polish`)."""
        if self.probs is not None:
            prob, U, stats = self.probs.polish(omega, prob, U, stats)
        sol = assemble_solution(prob, U, self.model, stats)
        pt = SweepPoint(omega / (2 * np.pi), sol, stats, how, [])
        red = prob.reduced
        if sol.success and red.Z.nbytes + red.obs_A.nbytes <= KEEP_PROBLEM_BYTES:
            pt.problem = prob
        if not sol.success:  # non-finite values (assemble_solution): a failure, no predictor
            pt.flags.append(f"not converged: {stats.message}")
            pt.seconds, pt.cpu_seconds = self.lap()
            return pt
        if self.flag is not None:
            pt.flags.extend(self.flag(sol))
        self.history.append((omega, U))
        self.last_solution = sol
        pt.seconds, pt.cpu_seconds = self.lap()
        return pt

    def add(self, omega, prob, U, stats, how) -> None:
        """An intermediate converged point (a substep, a point of the arclength branch);
        left out when :meth:`record` makes it a failure (its polish on the exact condensation
        failed, or it holds non-finite values)."""
        pt = self.record(omega, prob, U, stats, how)
        if pt.solution is not None and pt.solution.success:
            self.points.append(pt)

    def resume(self, probs: Problems, entries) -> None:
        """The points of a checkpoint (:func:`rebuild_point`), as if computed here."""
        for e in entries:
            pt = rebuild_point(probs, e)
            self.points.append(pt)
            if pt.solution is not None:
                self.history.append((e["omega"], e["U"]))
                self.last_solution = pt.solution
