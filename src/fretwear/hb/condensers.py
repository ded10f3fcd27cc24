"""The choice of the condensation: exact (eq. 19), modal (Craig-Bampton with its error check),
or automatic (docs/api.md, "Condensation"; docs/theory.md, "Large interfaces").

:func:`condenser` builds the condenser a caller passes as ``condenser=`` to every driver of
one model, and records what it chose and why in :class:`CondensationChoice` (the condenser's
``choice`` attribute: the run summary and the results file's attributes of the analyses).

The automatic rule (``method="auto"``) is a cost rule with an accuracy check. The exact
condensation costs, per harmonic and frequency, one complex sparse LU of ``Z_ii`` and ``m``
complex solves (``m`` contact DOFs); the modal one costs, once, one real LU of ``K_ii``, ``m``
real solves (``Psi``, and as many for the residual vectors), a shift-invert Lanczos and one
complex LU for its check, then only dense ``O(m^2 q)`` products per harmonic and frequency. It
pays off when the interior is large (:data:`AUTO_MIN_INTERIOR`: below, the exact condensation
is a few dense or small sparse solves and has no error), there is a frequency band to build it
for, and either the interior is large against the contact DOFs (:data:`AUTO_RATIO`) or the
balance keeps :data:`AUTO_HARMONICS` harmonics or more: one frequency of the exact
condensation then costs ``max_order`` complex LUs and ``max_order m`` complex solves, several
times the modal one's ``m`` to ``2 m`` real solves, whatever the ratio (a 3D pad with 1024
contact nodes, 4 interior DOFs per contact DOF, 7 harmonics). The modal condenser then
raises its number of modes until its error check passes (:data:`fretwear.hb.modal.MAX_MODES`
at most); if even that fails, the choice falls back to the exact condensation and says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fretwear.errors import InputError
from fretwear.hb.modal import CUTOFF, TOL, CheckFailed, modal_condenser
from fretwear.hb.reduce import exact_condenser
from fretwear.model.checks import model_argument
from fretwear.model.core import Model

#: the methods of :func:`condenser`
METHODS = ("auto", "exact", "modal")
#: ``auto``: at least this many interior DOFs for the modal condensation (below, the exact
#: one is a few small sparse solves per harmonic)
AUTO_MIN_INTERIOR = 2000
#: ``auto``: at least this many interior DOFs per contact DOF for the modal condensation
#: (the modal one's ``m`` solves at the start and its ``O(m^2 q)`` products per harmonic
#: gain nothing unless the interior solves they replace are much larger)
AUTO_RATIO = 8
#: ``auto``: from this many harmonics on, the modal condensation is chosen for any interior
#: of at least :data:`AUTO_MIN_INTERIOR` DOFs (module docstring)
AUTO_HARMONICS = 3
#: the residual vectors (the static correction of the omitted modes) are added up to this
#: many contact DOFs: they double the ``m`` solves of ``Psi`` and add ``m`` coordinates
RESIDUAL_MAX = 1024


@dataclass(frozen=True)
class CondensationChoice:
    """What :func:`condenser` chose.

    asked : the method asked (``auto``, ``exact``, ``modal``); method : the one built
    (``exact`` or ``modal``); reason : why (one line); f_max [Hz], max_order : the band of
    the modal condensation (NaN, 0 when exact); n_modes : fixed-interface modes kept; q :
    interior coordinates; residual : residual vectors in the basis; error : the relative
    error of the check (0 for the exact condensation); tol : its bound.
    """

    asked: str
    method: str
    reason: str
    f_max: float = math.nan
    max_order: int = 0
    n_modes: int = 0
    q: int = 0
    residual: bool = False
    error: float = 0.0
    tol: float = math.nan

    def summary(self) -> str:
        """One line for the run summary."""
        if self.method == "exact":
            return f"condensation: exact (asked {self.asked}: {self.reason})"
        return (f"condensation: modal (asked {self.asked}: {self.reason}), {self.n_modes} "
                f"modes, {self.q} interior coordinates"
                f"{' with residual vectors' if self.residual else ''}; error check "
                f"{self.error:.2e} <= tol {self.tol:g} at harmonic {self.max_order} of "
                f"{self.f_max:.6g} Hz")

    def attributes(self) -> dict:
        """The choice as results-file attributes (numbers and strings)."""
        return {"condensation": self.method, "condensation_asked": self.asked,
                "condensation_reason": self.reason,
                "condensation_modes": int(self.n_modes),
                "condensation_residual_vectors": int(self.residual),
                "condensation_error": float(self.error),
                "condensation_tol": float(self.tol),
                "condensation_f_max": float(self.f_max),
                "condensation_max_order": int(self.max_order)}


def sizes(model: Model) -> tuple[int, int]:
    """``(m, n_i)``: contact DOFs and interior DOFs (neither fixed nor contact) of ``model``."""
    m = int(np.asarray(model.contact.dofs).size)
    fixed = np.unique(np.asarray(model.fixed_dofs, dtype=np.int64)).size
    return m, int(model.ndof) - fixed - m


def auto_method(model: Model, f_max: float | None, max_order: int = 1) -> tuple[str, str]:
    """``(method, reason)`` of the automatic rule before its error check (module docstring)."""
    m, ni = sizes(model)
    if f_max is None:
        return "exact", "no frequency band (quasi-static)"
    if ni < AUTO_MIN_INTERIOR:
        return "exact", f"{ni} interior DOFs < {AUTO_MIN_INTERIOR}"
    if ni >= AUTO_RATIO * m:
        return "modal", f"{ni} interior DOFs >= {AUTO_RATIO} x {m} contact DOFs"
    if max_order >= AUTO_HARMONICS:
        return "modal", (f"{max_order} harmonics >= {AUTO_HARMONICS} on {ni} interior DOFs "
                         f"(exact: {max_order} complex LUs per frequency)")
    return "exact", (f"{ni} interior DOFs < {AUTO_RATIO} x {m} contact DOFs and "
                     f"{max_order} harmonics < {AUTO_HARMONICS}")


def _check(method, f_max, max_order, modes, cutoff, tol) -> None:
    if method not in METHODS:
        raise InputError(f"method = {method!r}: expected one of {', '.join(METHODS)}")
    if f_max is not None and (isinstance(f_max, bool) or not isinstance(f_max, int | float)
                              or not math.isfinite(f_max) or f_max <= 0):
        raise InputError(f"f_max = {f_max!r}: expected a positive frequency [Hz] or None")
    if isinstance(max_order, bool) or not isinstance(max_order, int | np.integer) \
            or max_order < 1:
        raise InputError(f"max_order = {max_order!r}: expected a harmonic order >= 1")
    if modes is not None and (isinstance(modes, bool) or not isinstance(modes, int)
                              or modes < 0):
        raise InputError(f"modes = {modes!r}: expected a number of modes >= 0 or None")
    if (isinstance(cutoff, bool) or not isinstance(cutoff, int | float)
            or not math.isfinite(cutoff) or cutoff <= 0):
        raise InputError(f"cutoff = {cutoff!r}: expected a positive multiple of the highest "
                         "harmonic frequency")
    if (isinstance(tol, bool) or not isinstance(tol, int | float) or not math.isfinite(tol)
            or tol <= 0):
        raise InputError(f"tol = {tol!r}: expected a positive relative error")
    if method == "modal" and f_max is None:
        raise InputError("method = 'modal': f_max (the highest excitation frequency [Hz]) is "
                         "required")


@model_argument
def condenser(model: Model, method: str = "auto", *, f_max: float | None = None,
              max_order: int = 1, modes: int | None = None, cutoff: float = CUTOFF,
              tol: float = TOL, residual: bool | None = None):
    """The condenser of ``model`` by ``method``, with its :class:`CondensationChoice` as its
    ``choice`` attribute; pass it as ``condenser=`` to every driver of ``model``.

    Parameters
    ----------
    model : the structure.
    method : ``"exact"`` (eq. 19 at each harmonic and frequency,
        :func:`~fretwear.hb.reduce.exact_condenser`), ``"modal"`` (Craig-Bampton,
        :class:`~fretwear.hb.modal.ModalCondenser`: one basis for every frequency up to
        ``f_max``, checked there against the exact condensation) or ``"auto"`` (the modal one
        where the interior is large against the contact DOFs, :func:`auto_method`, else, or
        when its check cannot pass, the exact one).
    f_max : highest excitation frequency [Hz] the condenser will be used at (the sweep's top,
        the solve's frequency); required by ``"modal"``; None with ``"auto"``: exact.
    max_order : highest harmonic order (the modal check is at ``max_order * f_max``).
    modes : modal: the number of fixed-interface modes (checked, not raised); None: every
        mode below ``cutoff * max_order * f_max``, raised until the check passes.
    cutoff : see ``modes``.
    tol : bound on the relative error of the check (``Z_r``, the condensed loads and the
        recovery of the observed interior DOFs on random probes at ``max_order * f_max``).
    residual : modal: add the residual vectors (the static correction of the omitted modes,
        :meth:`~fretwear.hb.modal.ModalCondenser._residual_vectors`); None: where ``m <=``
        :data:`RESIDUAL_MAX`.

    Raises
    ------
    InputError : a bad argument; ``"modal"`` whose check fails (with ``modes`` given, or after
        :data:`~fretwear.hb.modal.MAX_MODES` modes).
    """
    _check(method, f_max, max_order, modes, cutoff, tol)
    if residual is not None and not isinstance(residual, bool):
        raise InputError(f"residual = {residual!r}: expected True, False or None")
    if method == "exact":
        return _with(exact_condenser(model), CondensationChoice("exact", "exact", "asked"))
    reason = "asked"
    if method == "auto":
        chosen, reason = auto_method(model, f_max, int(max_order))
        if chosen == "exact":
            return _with(exact_condenser(model), CondensationChoice("auto", "exact", reason))
    if residual is None:
        residual = sizes(model)[0] <= RESIDUAL_MAX
    try:
        mc = modal_condenser(model, float(f_max), int(max_order), modes=modes, cutoff=cutoff,
                             tol=float(tol), raise_modes=modes is None, residual=residual)
    except CheckFailed as exc:
        if method == "modal":
            raise
        return _with(exact_condenser(model),
                     CondensationChoice("auto", "exact", f"the modal check failed: {exc}"))
    return _with(mc, CondensationChoice(method, "modal", reason, float(f_max), int(max_order),
                                        mc.n_modes, mc.q, bool(getattr(mc, "residual", False)),
                                        float(mc.error),
                                        float(tol)))


def _with(cond, choice: CondensationChoice):
    cond.choice = choice
    return cond
