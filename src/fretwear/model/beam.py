"""Euler-Bernoulli beam matrices (cubic Hermite elements) for small reference structures.

The virtual beam of Scheel, Weigele and Krack (J. Sound Vib. 2020) is a cantilever of this
kind with a Jenkins element at one node (docs/theory.md, "Nonlinear modes"); with
:func:`fretwear.model.matrices.from_matrices` and :func:`modal_damping` these matrices make
the model (benchmarks/nonlinear_modes.py). Every node has a deflection ``w`` [m] and a slope
``theta`` [rad]; node 0 is clamped (removed), so DOF ``2 (j - 1)`` is the deflection of node
``j`` (``j = 1 .. n_nodes - 1``) and ``2 (j - 1) + 1`` its slope.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg as sla

from fretwear.errors import InputError


def cantilever_matrices(length: float, height: float, thickness: float, E: float, rho: float,
                        n_nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """``(K, M)`` (2 (n_nodes - 1),) square: stiffness [N/m, N, N m] and consistent mass of a
    clamped-free beam of ``n_nodes`` equidistant nodes (node 0 clamped), bending in the
    direction of ``height``: ``EI = E t h^3 / 12``, ``rho A = rho t h``; the element matrices
    of cubic Hermite shape functions (exact for the static deflection under end loads)."""
    for name, v in (("length", length), ("height", height), ("thickness", thickness),
                    ("E", E), ("rho", rho)):
        if not (isinstance(v, int | float) and math.isfinite(v) and v > 0):
            raise InputError(f"{name} = {v!r}: expected a positive number")
    if isinstance(n_nodes, bool) or not isinstance(n_nodes, int) or n_nodes < 2:
        raise InputError(f"n_nodes = {n_nodes!r}: expected a whole number >= 2")
    EI = E * thickness * height ** 3 / 12.0
    rhoA = rho * thickness * height
    le = length / (n_nodes - 1)
    l2 = le * le
    ke = EI / le ** 3 * np.array([[12, 6 * le, -12, 6 * le],
                                  [6 * le, 4 * l2, -6 * le, 2 * l2],
                                  [-12, -6 * le, 12, -6 * le],
                                  [6 * le, 2 * l2, -6 * le, 4 * l2]])
    me = rhoA * le / 420.0 * np.array([[156, 22 * le, 54, -13 * le],
                                       [22 * le, 4 * l2, 13 * le, -3 * l2],
                                       [54, 13 * le, 156, -22 * le],
                                       [-13 * le, -3 * l2, -22 * le, 4 * l2]])
    n = 2 * n_nodes
    K = np.zeros((n, n))
    M = np.zeros((n, n))
    for e in range(n_nodes - 1):
        sl = slice(2 * e, 2 * e + 4)
        K[sl, sl] += ke
        M[sl, sl] += me
    return K[2:, 2:], M[2:, 2:]


def modal_damping(K, M, ratio: float) -> np.ndarray:
    """``C = M Phi diag(2 zeta w) Phi^T M`` [N s/m]: the viscous damping that gives every mode
    of ``(K, M)`` (``Phi`` mass-normalised) the damping ratio ``ratio`` and couples none."""
    if not (isinstance(ratio, int | float) and math.isfinite(ratio) and ratio >= 0):
        raise InputError(f"ratio = {ratio!r}: expected a damping ratio >= 0")
    K = np.asarray(K, dtype=float)
    M = np.asarray(M, dtype=float)
    w2, phi = sla.eigh(K, M)
    MP = M @ phi
    C = (MP * (2.0 * ratio * np.sqrt(np.maximum(w2, 0.0)))) @ MP.T
    return 0.5 * (C + C.T)
