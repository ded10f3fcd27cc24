"""Pseudo-arclength continuation of the DLFT balance in frequency (the rung ``"arclength"`` of a
sweep point, :mod:`fretwear.hb.attempts`): from the last two converged points of a sweep along
the response curve until the frequency passes the target, through folds where frequency is not
a good parameter; and the test that a fold lies ahead of the last converged points
(:func:`fold_ahead`), which puts that rung before the other solver's."""

from __future__ import annotations

import time

import numpy as np

from fretwear.hb.solvers import SolveStats

#: Newton iterations of an arclength corrector without halving its best residual after which
#: the step is shortened (rather than spending the rest of ``max_iter`` on a diverging step)
STALL_ITERATIONS = 5


def scaled_points(history):
    """The converged points ``(omega, U)`` of ``history`` as the arclength scales them:
    ``y = (U / sx, omega / sw)`` with ``sx = |U|`` and ``sw = |omega|`` of the last one."""
    w_last, U_last = history[-1]
    sx = max(float(np.linalg.norm(U_last)), 1e-30)
    sw = max(abs(float(w_last)), 1e-30)
    return [np.concatenate([np.ravel(U) / sx, [w / sw]]) for w, U in history]


def frequency_turn(history, omega_target: float) -> float | None:
    """The frequency [rad/s] where the branch through the last three converged points
    ``(omega, U)`` of ``history`` turns back, marching towards ``omega_target``; None where it
    does not (fewer than three points, two at one place, or not decelerating).

    The frequency along the branch as a function of its arclength ``s`` (the scaled
    variables of :func:`arclength`; ``s`` the chords between the points), ``omega(s)``, is
    the parabola through the three points. A fold is where ``d omega / ds`` vanishes: the
    parabola decelerates (``omega''`` against the march) and turns at its extremum. A straight
    or accelerating branch (``omega''`` along the march: the tangent turning back towards the
    frequency axis, as past a peak) has none."""
    if len(history) < 3:
        return None
    w = np.array([float(h[0]) for h in history[-3:]])
    y = scaled_points(history[-3:])
    d1, d2 = np.linalg.norm(y[1] - y[0]), np.linalg.norm(y[2] - y[1])
    if d1 == 0.0 or d2 == 0.0:
        return None
    # omega(s) = w2 + b (s - s2) + a (s - s2)^2 through s = -d1 - d2, -d2, 0 (divided
    # differences)
    g1, g2 = (w[1] - w[0]) / d1, (w[2] - w[1]) / d2
    a = (g2 - g1) / (d1 + d2)
    b = g2 + a * d2
    march = np.sign(omega_target - w[2])
    if march == 0.0 or march * (g2 - g1) >= -1e-9 * (abs(g1) + abs(g2)):
        return None  # not decelerating (straight to rounding)
    return float(w[2] - b * b / (4.0 * a))  # the extremum of the parabola


def fold_ahead(history, omega_target: float, halved_out: bool = False) -> bool:
    """Whether a fold lies between the last converged point of ``history`` and
    ``omega_target`` [rad/s]: the branch decelerates (:func:`frequency_turn`) and either its
    turn lies short of the target, or the step from the last point was halved to its smallest
    without converging (``halved_out``: no point of the branch a smallest step ahead).

    The turn of three points is an estimate: on the dovetail's FRF (docs/studies/
    fallbacks.md) the points at 2260, 2350 and 2395 Hz put it at 2404.5 Hz, where the
    arclength found the fold (2404.6 Hz); where the fold is a local feature of a slowly
    bending branch the parabola puts it too far (the bladed disk's at 2800 Hz: 2700, 2750 and
    2756.25 Hz put it at about 2800 Hz, the arclength found it at 2760.7 Hz, where the halved
    step had failed), which the halving's failure tells."""
    w_turn = frequency_turn(history, omega_target)
    if w_turn is None:
        return False
    return halved_out or bool(np.sign(omega_target - history[-1][0]) * (omega_target - w_turn)
                              > 0.0)


def arclength(probs, anchor, y_prev, y_last, omega_target, solver_tol, max_steps=20,
              max_iter=20):
    """Pseudo-arclength continuation from ``y_last`` (secant from ``y_prev``) until the
    frequency passes ``omega_target``. ``y = (U (m*H,), omega)``. Returns the list of converged
    ``(U, omega, stats, problem)`` along the branch (the last one is past or at the target) or
    [] (the problem is the one the point converged on: recording the point needs no new
    condensation)."""
    U1, w1 = y_last
    U0, w0 = y_prev
    sx = max(np.linalg.norm(U1), 1e-30)
    sw = max(abs(w1), 1e-30)

    def scaled(U, w):
        return np.concatenate([U / sx, [w / sw]])

    t = scaled(U1, w1) - scaled(U0, w0)
    ds = np.linalg.norm(t)
    if ds == 0:
        return []
    t /= ds
    if t[-1] * (omega_target - w1) < 0:  # march towards the target
        t = -t
    out = []
    yk = scaled(U1, w1)
    for _ in range(max_steps):
        converged = False
        for _shrink in range(4):
            yp = yk + ds * t
            y = yp.copy()
            t0 = time.perf_counter()
            nit = nf = 0
            fw = None
            best = []
            for _it in range(max_iter):
                U, w = y[:-1] * sx, y[-1] * sw
                if not (np.isfinite(w) and w > 0.0):
                    break  # a step past zero frequency: a shorter one (no balance there)
                prob = probs.get(w, anchor)
                f, J = prob.residual(U.reshape(prob.m, prob.H))
                nf += 1
                if fw is None:
                    # df/dw by a forward difference, once per corrector (a chord: each one
                    # costs a condensation at w + dw; the residual itself is exact at every
                    # iterate, so the converged point is the same)
                    dw = 1e-7 * w
                    f2, _ = probs.get(w + dw, anchor).residual(U.reshape(prob.m, prob.H),
                                                               False)
                    fw = (f2 - f) / dw
                g = t @ (y - yp)
                rel = np.linalg.norm(f) / prob.scale(U.reshape(prob.m, prob.H))
                if rel <= solver_tol:
                    converged = True
                    break
                best.append(rel)
                if len(best) > STALL_ITERATIONS and min(best[-STALL_ITERATIONS:]) > \
                        0.5 * min(best[:-STALL_ITERATIONS]):
                    break  # no progress: a shorter step rather than more iterations
                try:
                    dy = bordered_step(J, f, fw, g, t, sx, sw)
                except np.linalg.LinAlgError:
                    break
                if abs(dy[-1] * sw) > abs(omega_target - w1):
                    # a Newton step of the corrector that moves the frequency by more than
                    # the whole step to the target is diverging (seen past folds of the
                    # dovetail's FRF: 70 Hz jumps on an 18 Hz grid): a shorter step at once,
                    # rather than more iterates, each a condensation at a new frequency
                    break
                y = y + dy
                nit += 1
            if converged:
                break
            ds *= 0.5
        if not converged:
            return out
        U, w = y[:-1] * sx, y[-1] * sw
        st = SolveStats(True, float(np.linalg.norm(f) / prob.scale(U.reshape(prob.m, prob.H))),
                        nit, nf * 2, nf, time.perf_counter() - t0, "converged (arclength)",
                        "arclength")
        out.append((U, w, st, prob))
        tn = y - yk
        tn /= np.linalg.norm(tn)
        t = tn
        yk = y
        if (w - omega_target) * (omega_target - w1) >= 0:  # passed the target frequency
            break
        if nit <= 3:
            ds *= 1.5
    return out


def bordered_step(J, f, fw, g, t, sx, sw):
    """The Newton step ``dy`` of the arclength system ``[[J sx, fw sw], [t]] dy = -[f, g]``
    (scaled variables): by LU of the bordered matrix for a formed Jacobian, by block
    elimination with two solves of ``J`` for the operator of large interfaces
    (:class:`~fretwear.hb.krylov.KrylovJacobian`)."""
    n = f.size
    if isinstance(J, np.ndarray):
        A = np.zeros((n + 1, n + 1))
        A[:n, :n] = J * sx
        A[:n, n] = fw * sw
        A[n] = t
        return np.linalg.solve(A, -np.concatenate([f, [g]]))
    a, b = J.solve(np.column_stack([-f, fw * sw])).T  # J a = -f, J b = fw sw
    den = t[n] - t[:n] @ b / sx
    if not np.isfinite(den) or den == 0.0:
        raise np.linalg.LinAlgError("singular bordered system")
    dw = (-g - t[:n] @ a / sx) / den
    return np.concatenate([(a - dw * b) / sx, [dw]])
