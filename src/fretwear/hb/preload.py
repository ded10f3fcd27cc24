"""The contact under the static loads alone (the preload), applied from rest: the stick anchors
of the loading history "preload first, then vibrate" (:func:`preload_anchor`) and which nodes
the preload presses (:func:`preload_contact`). One static contact problem (the DLFT balance of
harmonic 0 on the quasi-static condensation), solved once.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from fretwear.hb.fourier import FourierBasis
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.reduce import Reduced, condense
from fretwear.hb.solvers import solve
from fretwear.model.core import Model

#: relative residual and iteration limit of the static contact problem under the preload
#: (:func:`preload_anchor`, :func:`preload_contact`)
STATIC_TOL = 1e-10
STATIC_MAX_ITER = 100


@dataclass
class StaticAnchor:
    """The stick anchors of the preload state (:func:`preload_anchor`).

    values : (nc, d-1) tangential positions of the contact nodes [m] after the static loads
    are applied from rest; 0 (the undeformed position) when the static contact problem did not
    converge. success : that problem converged. message : why its solver stopped.
    """

    values: np.ndarray
    success: bool
    message: str

    @property
    def warning(self) -> str:
        """One line for the user when the static solve failed (``""`` when it converged)."""
        if self.success:
            return ""
        return (f"the static contact problem under the preload did not converge "
                f"({self.message}): the stick anchors are set to 0 (the undeformed position) "
                "instead of the preload state, so the mean tangential positions of stuck "
                "nodes may be wrong")


def preload_anchor(model: Model, *, quasi: Reduced | None = None, eps="auto",
                   condenser=None) -> StaticAnchor:
    """Tangential positions of the contact nodes after the static loads are applied from rest,
    with whether the static solve converged.

    Solves the static contact problem (one instant) starting from a stress-free state in which
    every node that touches sticks where it is (anchor 0): the loading history "preload first,
    then vibrate". ``eps``: the penalty of this static solve (the rule or a number, as for
    :class:`DLFTProblem`). When it does not converge the anchors are 0 and the result says so
    (``success``, ``warning``): the callers put the warning in their results. ``condenser``:
    the condenser of the caller's run (default: :func:`fretwear.hb.reduce.exact_condenser`),
    used for the quasi-static condensation unless ``quasi`` gives it.
    """
    prob, x, st = _static_solve(model, quasi, eps, condenser)
    if not st.success:
        return StaticAnchor(np.zeros((prob.nc, prob.d - 1)), False, st.message)
    U = x.reshape(prob.nc, prob.d, 1)
    return StaticAnchor(U[:, 1:, 0].copy(), True, st.message)


def static_anchor(model: Model, *, quasi: Reduced | None = None, eps="auto",
                  condenser=None) -> np.ndarray:
    """The anchors of :func:`preload_anchor` alone, (nc, d-1) [m]; a
    :class:`RuntimeWarning` says when the static solve did not converge (the anchors are then
    0)."""
    a = preload_anchor(model, quasi=quasi, eps=eps, condenser=condenser)
    if not a.success:
        warnings.warn(a.warning, RuntimeWarning, stacklevel=2)
    return a.values


def _static_solve(model: Model, quasi: Reduced | None, eps, condenser=None):
    """The static contact problem of :func:`static_anchor`: ``(problem, x, stats)``."""
    basis = FourierBasis.static()
    red = quasi if quasi is not None else condense(model, 0.0, [0], quasi_static=True,
                                                   condenser=condenser)
    prob = DLFTProblem(red, model.contact, basis, eps=eps)
    U0 = prob.initial_guess()

    def fun(x, jac=True):
        return prob.residual(x.reshape(prob.m, prob.H), jac)

    x, _, st = solve(fun, U0.reshape(-1), lambda x: prob.scale(x.reshape(prob.m, prob.H)),
                     method="powell", tol=STATIC_TOL, max_iter=STATIC_MAX_ITER)
    return prob, x, st


@dataclass
class PreloadContact:
    """The contact of every interface under the static loads alone (the preload), applied
    from rest: what a vibration or a wear run starts from.

    normal_force : (nc,) normal contact force of each node [N] (compression positive; 0 where
        the node is open or touches without force), None when the static contact problem did
        not converge; loaded : (nc,) bool, nodes that carry a normal force (more than ``1e-9``
        of the largest static load or contact force) or have a prescribed normal load;
    names : the interface names; closed : (n_interfaces,) number of loaded nodes of each.
    """

    normal_force: np.ndarray | None
    loaded: np.ndarray
    names: tuple
    closed: np.ndarray
    message: str = ""

    @property
    def success(self) -> bool:
        """The static contact problem converged."""
        return self.normal_force is not None

    def open_interfaces(self) -> list[str]:
        """Names of the interfaces with no node in contact under the preload."""
        return [n for n, k in zip(self.names, self.closed, strict=True) if k == 0]


def preload_contact(model: Model, *, eps="static", condenser=None) -> PreloadContact:
    """Which contact nodes of ``model`` are pressed by its static loads (the preload).

    The static contact problem of :func:`static_anchor` (exact contact, Coulomb friction,
    loads applied from rest), solved once. An interface on which no node carries a normal
    force under the preload (opened by its gap, pulled away, or touching without force) is
    almost always a mistake in a vibration or wear run: its friction can only act where the
    vibration itself closes it. Nodes with a prescribed normal load count as in contact.
    ``condenser``: as for :func:`preload_anchor`.
    """
    c = model.contact
    names = c.names()
    where = c.interface_index()
    prescribed = np.zeros(c.n_nodes, dtype=bool)
    if c.normal_load is not None:
        prescribed = np.isfinite(np.asarray(c.normal_load.vector, dtype=float))
    prob, x, st = _static_solve(model, None, eps, condenser)
    if not st.success:
        loaded = prescribed
        lam_n = None
    else:
        lu, lx, _, _ = prob.time_law(x.reshape(prob.m, prob.H))
        lam = (lu - lx).reshape(prob.nc, prob.d)
        lam_n = lam[:, 0].copy()
        scale = max(float(np.max(np.abs(lam), initial=0.0)),
                    float(np.max(np.abs(prob.F), initial=0.0)))
        loaded = prescribed | (lam_n > 1e-9 * scale) if scale > 0 else prescribed.copy()
    closed = np.bincount(where[loaded], minlength=len(names))
    return PreloadContact(lam_n, loaded, tuple(names), closed,
                          st.message if not st.success else "converged")
