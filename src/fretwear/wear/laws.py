"""Wear laws: the wear depth per cycle of every contact node (paper eq. 29).

Per node, per cycle, evaluated on the converged DLFT samples with the *corrected* slip
``X_T(n) - X_T(n-1)``, which is exactly zero in stick:

* Archard (eq. 29): ``dW1_p = k_w sum_n p_N(n) |X_T(n) - X_T(n-1)|``, ``p_N = lambda_N/area``;
  at a node-to-node pair both surfaces wear, each at its own coefficient, and the gap opens
  by the sum (``k_w = k_w(a) + k_w(b)``; :func:`side_depths` splits it);
* energy (Fouvry et al. 2003): worn volume = ``k_e`` x friction energy, so
  ``dW1_p = k_e E_p / area_p`` with ``E_p = sum_n lambda_T(n).(X_T(n) - X_T(n-1))``; at a
  node-to-node pair each surface wears by its own coefficient times the energy dissipated
  between them (``k_e = k_e(a) + k_e(b)``, the partner's ``k_e(b)`` given apart).

With Coulomb slip ``E_p = mu sum_n lambda_N |dX_T|`` exactly, so both laws are ``c_p S_p`` with
the slip work ``S_p`` of :mod:`fretwear.wear.kernels` and ``c_p = k_w / area_p`` or
``k_e mu / area_p``; the worn volume per cycle of Archard's law is ``k_w / mu`` times the
friction energy per cycle.
"""

from __future__ import annotations

import numpy as np

from fretwear.errors import InputError
from fretwear.hb.solution import PeriodicSolution
from fretwear.model.core import Model

LAWS = ("archard", "energy")


def wear_coefficients(model: Model, law_name: str = "archard",
                      energy_coefficient: float | None = None,
                      partner_energy_coefficient: float | None = None) -> np.ndarray:
    """Per-node factor ``c_p`` [1/N] with ``dW1_p = c_p S_p`` (module docstring).

    Parameters
    ----------
    model : the model (``contact.wear_coefficient`` k_w [1/Pa], ``contact.area`` [m^2],
        ``contact.mu``).
    law_name : ``"archard"`` (eq. 29, ``c = k_w / area``) or ``"energy"``
        (``c = k_e mu / area``).
    energy_coefficient : ``k_e`` [m^3/J] of the energy law (the surface of every contact
        node).
    partner_energy_coefficient : ``k_e`` [m^3/J] of the partner surfaces of node-to-node
        pairs (None: they do not wear).
    """
    c = model.contact
    area = np.asarray(c.area, dtype=float)
    if law_name == "archard":
        k = c.wear_nodes() + c.partner_wear_nodes()  # both surfaces of a pair wear
        if not np.all(k >= 0):
            raise InputError(f"wear_coefficient = {c.wear_coefficient!r}: expected k_w >= 0 "
                             "[1/Pa]")
        return k / area
    if law_name == "energy":
        if energy_coefficient is None or not float(energy_coefficient) >= 0:
            raise InputError(f"energy_coefficient = {energy_coefficient!r}: the energy law needs "
                             "k_e >= 0 [m^3/J]")
        ka, kb = energy_sides(model, energy_coefficient, partner_energy_coefficient)
        return (ka + kb) * c.mu_nodes() / area
    raise InputError(f"law = {law_name!r}: expected one of {LAWS}")


def coefficient_keys(law_name: str) -> str:
    """What sets the wear factors of :func:`wear_coefficients` under ``law_name``, for a run
    whose factors are all 0 to say (the Archard law: the contact's k_w; the energy law: k_e
    and the friction coefficient it multiplies)."""
    return ("the contact's wear_coefficient" if law_name == "archard" else
            "energy_coefficient and the contact's mu")


def energy_sides(model: Model, energy_coefficient, partner_energy_coefficient=None):
    """Energy-law coefficients ``(k_e(a), k_e(b))`` (nc,) [m^3/J] of the two surfaces of every
    contact node: ``k_e(b)`` is 0 at a node-to-rigid node and without a partner coefficient."""
    n = model.contact.n_nodes
    ka = np.full(n, float(energy_coefficient))
    if partner_energy_coefficient is None:
        return ka, np.zeros(n)
    kb = float(partner_energy_coefficient)
    if not kb >= 0:
        raise InputError(f"partner_energy_coefficient = {partner_energy_coefficient!r}: "
                         "expected k_e >= 0 [m^3/J]")
    return ka, np.where(model.contact.paired(), kb, 0.0)


def wear_per_cycle(sol: PeriodicSolution, *, law_name: str = "archard",
                   wear_coefficient: float = 0.0,
                   energy_coefficient: float | None = None) -> np.ndarray:
    """Wear depth per cycle ``dW1`` per node (nc,) [m] of a converged periodic solution.

    Archard (eq. 29 with the corrected slip): ``k_w sum_n p_N(n) |X_T(n) - X_T(n-1)|``, from
    :meth:`~fretwear.hb.solution.PeriodicSolution.pressure_t` and
    :meth:`~fretwear.hb.solution.PeriodicSolution.slip_t` (zero in stick, so a node that sticks all
    period does not wear). Energy law (Fouvry et al. 2003): ``k_e E_p / area_p`` with ``E_p``
    from :meth:`~fretwear.hb.solution.PeriodicSolution.friction_energy`.

    This is the post-processing route; the integrators use the kernel
    :func:`fretwear.wear.kernels.slip_work`, which gives the same numbers.
    """
    if law_name == "archard":
        return float(wear_coefficient) * np.sum(sol.pressure_t() * sol.slip_t(), axis=1)
    if law_name == "energy":
        if energy_coefficient is None:
            raise InputError("the energy law needs energy_coefficient k_e [m^3/J]")
        return float(energy_coefficient) * sol.friction_energy() / sol.area
    raise InputError(f"law = {law_name!r}: expected one of {LAWS}")


def side_depths(model: Model, wear, law_name: str = "archard",
                energy_coefficient: float | None = None,
                partner_energy_coefficient: float | None = None
                ) -> tuple[np.ndarray, np.ndarray]:
    """Worn depths ``(W_a, W_b)`` [m] of the two surfaces of every contact node from the
    total ``wear`` (..., nc) [m] by which the gap opened.

    Both laws wear each surface at its own coefficient under the same pressure and slip
    (eq. 29) or the same dissipated energy, so ``W_side = k(side) / (k(a) + k(b)) W``; a
    node-to-rigid node and a pair whose partner's coefficient is 0 (or, with the energy law,
    not given) put all of ``W`` on the surface of node ``a``.
    """
    c = model.contact
    W = np.asarray(wear, dtype=float)
    if law_name == "archard":
        ka, kb = c.wear_nodes(), c.partner_wear_nodes()
    else:
        ka, kb = energy_sides(model, 1.0 if energy_coefficient is None else energy_coefficient,
                              partner_energy_coefficient)
    tot = ka + kb
    share_b = np.divide(kb, tot, out=np.zeros_like(tot), where=tot > 0)
    Wb = W * share_b
    return W - Wb, Wb


def worn_volume(wear: np.ndarray, area: np.ndarray) -> float:
    """Worn volume ``sum_p area_p W_p`` [m^3] of wear depths ``W`` [m]."""
    return float(np.dot(np.asarray(area, float), np.asarray(wear, float)))


def zero_wear_zones(x, wear, fraction: float = 0.01) -> list[list[float]]:
    """Intervals ``[x_first, x_last]`` [m] of consecutive contact nodes (ordered by ``x``)
    whose wear depth is at most ``fraction`` of the deepest: the "pillars" and nodal zones of
    the paper (section 4.2.2-4.2.3)."""
    x = np.asarray(x, float)
    w = np.asarray(wear, float)
    order = np.argsort(x)
    x, w = x[order], w[order]
    low = w <= fraction * max(float(w.max()), 1e-300)
    zones, start = [], None
    for i, z in enumerate(low):
        if z and start is None:
            start = i
        if not z and start is not None:
            zones.append([float(x[start]), float(x[i - 1])])
            start = None
    if start is not None:
        zones.append([float(x[start]), float(x[-1])])
    return zones
