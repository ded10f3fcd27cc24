"""A mistuned disk: the ``N`` sectors of a :class:`~fretwear.model.cyclic.CyclicSector` made
to differ, one factor per sector, and the amplification of the blade response it causes.

No two blades of a real disk are alike: their Young's moduli, their roots' friction and wear
coefficients scatter by a few per cent. The cyclic reduction then no longer holds (the
harmonics of a travelling wave spread over every harmonic index), and the disk is assembled
whole (:func:`mistuned_disk`, the assembly of :func:`fretwear.model.cyclic.whole_disk`) with
sector ``j``'s stiffness ``f_E,j K`` (and hysteretic damping ``f_E,j D``: a loss factor is a
property of the material), its contact's friction coefficients ``f_mu,j mu`` and wear
coefficients ``f_w,j k_w``. The mass and the viscous damping are those of the tuned sector.
With every factor 1 the mistuned disk *is* the tuned disk.

The largest blade response of a mistuned disk over that of the tuned one (every blade of the
tuned disk responds alike under a travelling wave) is its *amplification factor*
(:func:`amplification_factor`). Whitehead (1966; J. Mech. Eng. Sci. 8, 1966, and the proof of
1998, ASME J. Eng. Gas Turbines Power 120) showed that in a disk whose blades share one mode
family, mistuning cannot amplify the forced response by more than

    A_max = (1 + sqrt(N)) / 2                                   (:func:`whitehead_bound`),

the bound being approached when the coupling between blades is weak, of the order of the
mistuning's spread: with a strong coupling the disk's modes stay travelling waves, with none
the blades respond each on its own.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from fretwear.errors import InputError
from fretwear.model.checks import amplitudes, model_argument, whole_number
from fretwear.model.core import Model, ObservedPoint
from fretwear.model.cyclic import (
    CyclicSector,
    _disk_contact,
    _disk_numbering,
    _wave_loads,
    sector_maps,
)
from fretwear.resources import require_memory

#: the kinds of mistuning factors, one per sector each
KINDS = ("young", "mu", "wear")


@dataclass(frozen=True)
class Mistuning:
    """One factor per sector (``N`` each, 1 = tuned): ``young`` on the sector's stiffness
    (its Young's modulus), ``mu`` on its contact's friction coefficients, ``wear`` on its
    contact's wear coefficients (its own surface and its partner's)."""

    young: np.ndarray
    mu: np.ndarray
    wear: np.ndarray

    @property
    def n_sectors(self) -> int:
        return int(self.young.size)

    @property
    def tuned(self) -> bool:
        """Every factor is exactly 1."""
        return all(bool(np.all(getattr(self, k) == 1.0)) for k in KINDS)


def _factors(values, kind: str, n: int) -> np.ndarray:
    if values is None:
        return np.ones(n)
    try:
        f = np.asarray(values, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InputError(f"mistuning {kind} = {values!r}: expected {n} numbers (one factor "
                         "per sector)") from None
    if f.size != n:
        raise InputError(f"mistuning {kind}: {f.size} factors given; expected {n} (one per "
                         "sector)")
    if not np.all(np.isfinite(f)) or np.any(f <= 0):
        raise InputError(f"mistuning {kind} = {np.round(f, 6).tolist()}: expected positive "
                         "factors (1 = tuned)")
    return f


def mistuning(n_sectors: int, *, young=None, mu=None, wear=None) -> Mistuning:
    """The :class:`Mistuning` of a disk of ``n_sectors`` sectors: each of ``young``, ``mu``,
    ``wear`` is ``n_sectors`` positive factors (sector 0 first) or None (all 1)."""
    if isinstance(n_sectors, bool) or not isinstance(n_sectors, int | np.integer) \
            or n_sectors < 2:
        raise InputError(f"n_sectors = {n_sectors!r}: expected an integer >= 2")
    n = int(n_sectors)
    require_memory(8.0 * 2 * len(KINDS) * n, f"the mistuning factors of {n:,} sectors")
    return Mistuning(_factors(young, "young", n), _factors(mu, "mu", n),
                     _factors(wear, "wear", n))


def random_mistuning(n_sectors: int, std: float, seed: int, kinds=("young",)) -> Mistuning:
    """A seeded random :class:`Mistuning`: factors ``1 + std z`` with ``z`` standard normal
    (``numpy.random.default_rng(seed)``, drawn sector by sector, kind after kind in the
    order of :data:`KINDS`) for each kind in ``kinds``; the others 1. ``std`` must keep
    every factor positive (a few per cent, as measured on real disks)."""
    n_sectors = whole_number(n_sectors, "n_sectors", low=1)
    if isinstance(std, bool) or not isinstance(std, int | float) or not 0 <= std < 0.5:
        raise InputError(f"mistuning std = {std!r}: expected a standard deviation in [0, 0.5)")
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or not \
            0 <= seed <= 2**62:
        raise InputError(f"mistuning seed = {seed!r}: expected an integer >= 0")
    unknown = [k for k in kinds if k not in KINDS]
    if unknown or not kinds:
        raise InputError(f"mistuning kinds = {list(kinds)!r}: expected some of {list(KINDS)}")
    require_memory(8.0 * 3 * len(KINDS) * int(n_sectors),
                   f"the mistuning factors of {int(n_sectors):,} sectors")
    rng = np.random.default_rng(int(seed))
    draws = {k: 1.0 + float(std) * rng.standard_normal(int(n_sectors)) for k in KINDS}
    return mistuning(n_sectors, **{k: draws[k] for k in kinds})


def whitehead_bound(n_sectors: int) -> float:
    """Whitehead's largest amplification of a mistuned disk's forced response,
    ``(1 + sqrt(N)) / 2`` (one mode family; module docstring)."""
    n_sectors = whole_number(n_sectors, "n_sectors", low=1)
    return 0.5 * (1.0 + np.sqrt(float(n_sectors)))


def sector_point_name(name: str, j: int) -> str:
    """The name of observed point ``name`` of sector ``j`` in a mistuned disk."""
    return f"{name}@{j}"


@model_argument
def mistuned_disk(sector: CyclicSector, engine_order: int, mistuned: Mistuning) -> Model:
    """The disk of ``N`` sectors, sector ``j`` mistuned by the ``j``-th factors of
    ``mistuned`` (module docstring), under the travelling wave of ``engine_order`` (the
    loads of :func:`~fretwear.model.cyclic.whole_disk`); every observed point of the sector
    on every sector, named ``"<name>@<j>"`` (positions turned into the disk's axes)."""
    engine_order = whole_number(engine_order, "engine_order")
    n = sector.n_sectors
    if not isinstance(mistuned, Mistuning) or mistuned.n_sectors != n:
        got = mistuned.n_sectors if isinstance(mistuned, Mistuning) else mistuned
        raise InputError(f"mistuning: {got!r} sectors; expected a Mistuning of the disk's "
                         f"{n} sectors")
    m = sector.model
    A, nd = sector_maps(sector)

    def assemble(X, factors):
        if X is None:
            return None
        X = sp.csr_matrix(X)
        return sum((f * (Aj @ X @ Aj.T) for f, Aj in zip(factors, A, strict=True)),
                   sp.csr_matrix((nd, nd))).tocsr()

    ones = np.ones(n)
    maps, _ = _disk_numbering(sector)
    fixed = np.unique(np.concatenate([maps[j, np.asarray(m.fixed_dofs, np.int64)]
                                      for j in range(n)]))
    c = m.contact
    nc = c.n_nodes
    base = dataclasses.replace(
        c, mu=np.broadcast_to(np.asarray(c.mu, float), (nc,)).copy(),
        wear_coefficient=np.broadcast_to(np.asarray(c.wear_coefficient, float), (nc,)).copy(),
        partner_wear_coefficient=np.broadcast_to(
            np.asarray(c.partner_wear_coefficient, float), (nc,)).copy())
    disk_c = _disk_contact(sector, base, maps)
    disk_c = dataclasses.replace(
        disk_c, mu=disk_c.mu * np.repeat(mistuned.mu, nc),
        wear_coefficient=disk_c.wear_coefficient * np.repeat(mistuned.wear, nc),
        partner_wear_coefficient=disk_c.partner_wear_coefficient * np.repeat(mistuned.wear,
                                                                             nc))
    pt = sector.point[:sector.dim]
    observed = []
    for p in m.observed:
        for j in range(n):
            xyz = None if p.coords is None else \
                pt + (np.asarray(p.coords, float) - pt) @ sector.turn(j).T
            observed.append(ObservedPoint(sector_point_name(p.name, j),
                                          maps[j, np.asarray(p.dofs, np.int64)], xyz))
    return dataclasses.replace(
        m, K=assemble(m.K, mistuned.young), M=assemble(m.M, ones), C=assemble(m.C, ones),
        D=assemble(m.D, mistuned.young),
        loads=_wave_loads(m.loads, A, int(engine_order), sector.angle), contact=disk_c,
        observed=observed, fixed_dofs=fixed, mesh=None,
        meta={"mistuning": mistuned, "engine_order": int(engine_order), "sector": sector},
        name=f"{m.name} (mistuned disk of {n})")


@model_argument
def sector_responses(sector: CyclicSector, U) -> np.ndarray:
    """``U`` (..., ndof_disk) of the whole disk as each sector's DOFs in its own axes:
    (..., N, ndof) (sector ``j``'s are ``A_j^T U``, :func:`~fretwear.model.cyclic.sector_maps`)."""
    A, nd = sector_maps(sector)
    U = amplitudes(U, "U")
    if U.shape[-1:] != (nd,):
        raise InputError(f"U has shape {U.shape}; expected (..., {nd}): the disk's DOFs last")
    flat = U.reshape(-1, nd)
    out = np.stack([(Aj.T @ flat.T).T for Aj in A], axis=1)
    return out.reshape((*U.shape[:-1], sector.n_sectors, sector.model.ndof))


def blade_amplitudes(amplitude) -> np.ndarray:
    """The response of each blade from the amplitudes of its observed point, ``amplitude``
    (..., N, d) [m] (the moduli of the point's components in any axes: sector ``j``'s or
    the disk's): ``(..., N)`` the length ``sqrt(sum_c |U_c|^2)`` of the complex amplitude
    vector, which no rotation changes."""
    a = amplitudes(amplitude, "amplitude", nan=True)
    return np.sqrt(np.sum(np.abs(a) ** 2, axis=-1))


def amplification_factor(mistuned, tuned) -> float:
    """The largest blade response of the mistuned disk over the tuned disk's largest:
    ``max(mistuned) / max(tuned)`` over every blade (and frequency) given [-]."""
    for name, value in (("mistuned", mistuned), ("tuned", tuned)):
        a = amplitudes(value, name, nan=True)
        if a.dtype.kind == "c" or np.nanmin(a) < 0:
            raise InputError(f"{name} holds {np.nanmin(a.real):g}; expected blade responses "
                             ">= 0 (moduli, e.g. blade_amplitudes)")
    top = float(np.nanmax(np.asarray(tuned, float)))
    if not np.isfinite(top) or top <= 0:
        raise InputError(f"tuned response max {top!r}: expected a positive amplitude")
    return float(np.nanmax(np.asarray(mistuned, float))) / top
