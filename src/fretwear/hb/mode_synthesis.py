"""Forced response synthesised from one nonlinear mode (single-nonlinear-mode theory; Krack,
J. Sound Vib. 2015, section 4; Szemplinska-Stupnicka's single-mode method).

Near a well separated resonance the forced periodic response is taken to be the nonlinear
mode at the amplitude ``a`` it reaches: ``u = Re(a phi(a) e^{i W t}) + ...`` with the mode's
mass-normalised shape ``phi(a)`` (``phi^H M phi = 1``, the fundamental harmonic of
:class:`~fretwear.hb.nonlinear_modes.ModePoint`), its circular frequency ``w(a)`` and the
damping the EPMC compensates, ``xi(a) = 2 zeta(a) w(a)``. Projecting the balance at the
excitation frequency ``W`` on ``phi`` gives the scalar equation

    (w(a)^2 - W^2 + i xi(a) W) a = phi(a)^H F_1

(``F_1`` the loads' first harmonic, ``F(t) = Re(F_1 e^{i W t})``). Its modulus is a
quadratic equation in ``W^2``: with ``f = |phi^H F_1|``,

    W^2 = w^2 - xi^2 / 2 +- sqrt((f / a)^2 - xi^2 (w^2 - xi^2 / 4)),

two excitation frequencies per amplitude below the peak, none above it; the peak is where
the root vanishes, ``f / a = xi sqrt(w^2 - xi^2 / 4)``.

What it neglects: the other modes (the projection), the mode's change of shape with ``W``
at fixed ``a``, and the frequency dependence of the damping: the EPMC measures the
dissipation per cycle as a viscous term at the mode's own frequency, ``xi w a^2 pi``, while a
friction joint dissipates per cycle the same energy at any frequency (hysteretic); at ``W``
the synthesis damps ``xi W`` instead of ``xi w``, a relative error ``|W / w - 1|`` on the
friction part of the damping term (about ``zeta^2`` at the peak). ``damping="hysteretic"``
takes the other reading, the whole compensated damping rate-independent,

    (w(a)^2 - W^2 + i xi(a) w(a)) a = phi(a)^H F_1,
    W^2 = w^2 +- sqrt((f / a)^2 - xi^2 w^2),

exact for a single-DOF oscillator whose only damping is a rate-independent joint, kept to
one harmonic (the describing function of a Jenkins element depends on the amplitude only).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from fretwear.errors import InputError
from fretwear.hb.dynamics import StructureDynamics, structure_dynamics
from fretwear.hb.nonlinear_modes import Backbone, ModeSystem, mode_system
from fretwear.model.core import Model


@dataclass
class ModalFRF:
    """Forced response synthesised from one nonlinear mode (:func:`synthesize`), per
    backbone point (in increasing amplitude).

    amplitude : (k,) modal amplitude ``a`` [m sqrt(kg)]; modal_force : (k,) ``|phi^H F_1|``
    [N / sqrt(kg)]; omega_lo, omega_hi : (k,) the two excitation frequencies at which the
    forced response reaches ``a`` [rad/s] (NaN above the peak: no real root; ``omega_lo``
    NaN too where ``W^2 <= 0``); observed : (k, no) the amplitude of the fundamental harmonic
    of the observed DOFs at the point [m] (None when the structure has no map); peak :
    index of the largest amplitude reached (the last point with a real root; -1 if none).
    """

    amplitude: np.ndarray
    modal_force: np.ndarray
    omega_lo: np.ndarray
    omega_hi: np.ndarray
    observed: np.ndarray | None
    peak: int

    def curve(self, observed: int | None = None):
        """``(frequency [Hz], amplitude)`` of the synthesised FRF along the branch: up the
        lower frequencies to the peak, down the upper ones (``observed``: index of the
        observed DOF to plot, default the modal amplitude)."""
        amp = self.amplitude if observed is None else self.observed[:, observed]
        ok_lo, ok_hi = np.isfinite(self.omega_lo), np.isfinite(self.omega_hi)
        f = np.concatenate([self.omega_lo[ok_lo], self.omega_hi[ok_hi][::-1]]) / (2 * np.pi)
        return f, np.concatenate([amp[ok_lo], amp[ok_hi][::-1]])


DAMPING = ("viscous", "hysteretic")


def excitation_frequencies(omega, xi, amplitude, modal_force, damping: str = "viscous"):
    """The two roots ``(W_lo, W_hi)`` [rad/s] of ``|w^2 - W^2 + i xi W| a = f``
    (``damping="viscous"``) or ``|w^2 - W^2 + i xi w| a = f`` (``"hysteretic"``; module
    docstring) for arrays ``omega`` [rad/s], ``xi`` [1/s], ``amplitude`` and ``modal_force``
    (broadcast); NaN where there is no real positive root."""
    if damping not in DAMPING:
        raise InputError(f"damping = {damping!r}: expected one of {DAMPING}")
    w, x, a, f = np.broadcast_arrays(*(np.asarray(v, dtype=float)
                                       for v in (omega, xi, amplitude, modal_force)))
    if damping == "viscous":
        centre = w * w - 0.5 * x * x
        disc = (f / a) ** 2 - x * x * (w * w - 0.25 * x * x)
    else:
        centre = w * w
        disc = (f / a) ** 2 - (x * w) ** 2
    root = np.sqrt(np.where(disc >= 0.0, disc, np.nan))
    hi2, lo2 = centre + root, centre - root
    hi = np.sqrt(np.where(hi2 > 0.0, hi2, np.nan))
    lo = np.sqrt(np.where(lo2 > 0.0, lo2, np.nan))
    return lo, hi


def modal_forces(model: Model, backbone: Backbone, *, dyn: StructureDynamics | None = None,
                 system: ModeSystem | None = None) -> np.ndarray:
    """``|phi(a)^H F_1|`` (k,) [N / sqrt(kg)] at every point of ``backbone``: the loads'
    first harmonic (``model.loads``, on the structure's coordinates,
    :attr:`~fretwear.hb.dynamics.StructureDynamics.load1_x`) projected on the mode's
    fundamental harmonic, mass-normalised over the whole structure. ``dyn``: the
    structure the backbone was computed on (default: the exact one of ``model``)."""
    dyn = structure_dynamics(model) if dyn is None else dyn
    if dyn.load1_x is None:
        raise InputError("the structure's dynamics carry no first-harmonic loads "
                         "(load1_x): expected structure_dynamics(model)")
    if system is None:
        system = dataclasses.replace(mode_system(model, dyn=dyn), masters=backbone.masters)
    m = system.m
    F = np.concatenate([dyn.load1_x, dyn.load1_q]).astype(complex)
    xx, xq, qx, qq = (np.asarray(b, dtype=float) for b in dyn.blocks["M"])
    M = np.block([[xx, xq], [qx, qq]]) if dyn.q else xx
    basis = backbone.basis
    h1 = int(np.flatnonzero(np.asarray(basis.orders) == 1)[0])
    out = np.empty(len(backbone.points))
    for i, p in enumerate(backbone.points):
        U = basis.to_complex(system.coordinates(p.Y, p.omega, p.xi, basis))[h1]
        if U.size != m + dyn.q:
            raise InputError(f"the backbone has {U.size} coordinates, the structure "
                             f"{m + dyn.q}: expected the dynamics it was computed on")
        norm = np.sqrt(max(float(np.real(np.vdot(U, M @ U))), 1e-300))
        out[i] = abs(np.vdot(U / norm, F))
    return out


def synthesize(backbone: Backbone, modal_force, *, damping: str = "viscous") -> ModalFRF:
    """The forced response of single-nonlinear-mode theory (module docstring) along
    ``backbone``, for the modal force ``|phi^H F_1|`` [N / sqrt(kg)]: a number, or (k,) per
    point (:func:`modal_forces`); ``damping``: ``"viscous"`` (the EPMC's own reading,
    ``xi W``) or ``"hysteretic"`` (``xi w``)."""
    if not backbone.points:
        raise InputError("synthesize: the backbone has no converged point")
    a = backbone.array("amplitude")
    f = np.broadcast_to(np.asarray(modal_force, dtype=float), a.shape).copy()
    if np.any(~np.isfinite(f)) or np.any(f <= 0):
        bad = f[~(np.isfinite(f) & (f > 0))]
        raise InputError(f"modal_force: {bad.size} of {f.size} values not positive (e.g. "
                         f"{bad[0]!r}): expected positive values, a number or one per "
                         "backbone point (no periodic load, or one the mode leaves "
                         "unexcited?)")
    lo, hi = excitation_frequencies(backbone.array("omega"), backbone.array("xi"), a, f,
                                    damping)
    obs = None
    if all(p.observed is not None for p in backbone.points):
        h1 = int(np.flatnonzero(np.asarray(backbone.basis.orders) == 1)[0])
        obs = np.array([np.abs(backbone.basis.to_complex(p.observed)[h1])
                        for p in backbone.points])
    reached = np.flatnonzero(np.isfinite(hi))
    return ModalFRF(amplitude=a, modal_force=f, omega_lo=lo, omega_hi=hi, observed=obs,
                    peak=int(reached[-1]) if reached.size else -1)
