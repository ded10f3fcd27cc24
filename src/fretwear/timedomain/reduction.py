"""The reduced dynamic model of the time integration: Craig-Bampton on the contact DOFs with
the fixed-interface modes below a cutoff and one static mode per load vector, diagonalised
(see :mod:`fretwear.timedomain.integrate` for the scheme)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from fretwear.errors import InputError
from fretwear.model.core import Model
from fretwear.model.interfaces import relative_model
from fretwear.timedomain.checks import check_contact, count, positive

CUTOFF_STEPS = 8  # default cutoff: modes whose period spans at least this many steps
DENSE_EIG_LIMIT = 3000  # interior DOFs up to which the fixed-interface modes are found densely
HF_LIMIT = 1.0  # hf_damping: modes with omega_j h above this (< 2 pi steps per period) ...
HF_GAMMA = 1.0  # ... are integrated with this Newmark gamma (spectral radius 1/3 at infinity)


# --------------------------------------------------------------------------------------------
# reduction (Craig-Bampton on the contact DOFs + static load modes, then diagonalised)
# --------------------------------------------------------------------------------------------
@dataclass
class ReducedDynamics:
    free: np.ndarray  # free DOFs of the model
    basis: np.ndarray  # (nf, r): U_free = basis @ q
    K: np.ndarray  # (r,) if diag else (r, r)
    M: np.ndarray
    C: np.ndarray  # (r,) diagonal part if diag (the damping is diag(C) + U R U^T)
    U: np.ndarray  # (r, s) low-rank damping factor (diag only)
    R: np.ndarray  # (s, s)
    diag: bool
    modal: bool  # basis M-orthonormal (basis^T M basis = I)
    Tx: np.ndarray  # (m, r) local contact displacements
    obs: np.ndarray  # (no, r) rows of the observed DOFs
    obs_names: list
    obs_slices: list
    info: dict


def submatrix(A, rows, cols):
    return A[rows][:, cols]


def fixed_interface_modes(Kii, Mii, w_cut: float | None, n_modes: int | None):
    """Eigenpairs of ``Kii phi = w^2 Mii phi`` (mass-normalised), below ``w_cut`` or the first
    ``n_modes``."""
    ni = Kii.shape[0]
    if ni == 0 or n_modes == 0:
        return np.zeros(0), np.zeros((ni, 0))
    if ni <= DENSE_EIG_LIMIT:
        Kd, Md = Kii.toarray(), Mii.toarray()
        try:
            if n_modes is not None:
                k = min(n_modes, ni)
                w2, V = sla.eigh(Kd, Md, subset_by_index=(0, k - 1))
            else:
                w2, V = sla.eigh(Kd, Md, subset_by_value=(-np.inf, w_cut**2))
        except np.linalg.LinAlgError as exc:
            raise InputError("the interior mass matrix (contact DOFs held) is not positive "
                             f"definite ({exc}); use modal_cutoff='all'") from None
        return w2, V
    # large models: shift-invert Lanczos, increasing the count until past the cutoff
    k = n_modes if n_modes is not None else 20
    while True:
        k = min(k, ni - 2)
        w2, V = spla.eigsh(Kii.tocsc(), k=k, M=Mii.tocsc(), sigma=0.0, which="LM",
                           v0=np.random.default_rng(0).standard_normal(Kii.shape[0]))
        order = np.argsort(w2)
        w2, V = w2[order], V[:, order]
        if n_modes is not None:
            return w2, V
        if w2[-1] > w_cut**2 or k >= ni - 2:
            keep = w2 <= w_cut**2
            return w2[keep], V[:, keep]
        k *= 2


def damping_split(K, M, C):
    """Write ``C = a K + b M + R`` with ``R`` non-zero on few DOFs.

    Structural damping is usually Rayleigh-like (``a K0 + b M``, or ``eta K0 / omega`` for a
    hysteretic loss factor) while springs to ground are undamped, so ``C - a K - b M`` lives
    on the spring DOFs only. ``a, b`` are fitted on the entries of the matrices, leaving out
    the rows that do not fit (robust least squares). Returns ``(a, b, S, R_SS)`` with ``S``
    the DOFs where ``R`` is non-zero; ``S`` may be large when ``C`` has no such structure.
    """
    scale = abs(C).max() if C.nnz else 0.0
    if scale == 0.0:
        return 0.0, 0.0, np.zeros(0, dtype=np.int64), np.zeros((0, 0))
    pat = (abs(K) + abs(M) + abs(C)).tocoo()
    rows, cols = pat.row, pat.col
    kv = np.asarray(K[rows, cols]).ravel()
    mv = np.asarray(M[rows, cols]).ravel()
    cv = np.asarray(C[rows, cols]).ravel()
    sk = np.abs(kv).max() or 1.0
    sm = np.abs(mv).max() or 1.0
    kn, mn = kv / sk, mv / sm
    # per-row 2x2 least squares, then the median over the rows (outlier rows are few)
    n = K.shape[0]
    skk = np.bincount(rows, kn * kn, n)
    skm = np.bincount(rows, kn * mn, n)
    smm = np.bincount(rows, mn * mn, n)
    skc = np.bincount(rows, kn * cv, n)
    smc = np.bincount(rows, mn * cv, n)
    det = skk * smm - skm**2
    ok = det > 1e-12 * (skk * smm + 1e-300)
    if ok.any():
        a = float(np.median((smm * skc - skm * smc)[ok] / det[ok]))
        b = float(np.median((skk * smc - skm * skc)[ok] / det[ok]))
    else:
        coef = np.linalg.lstsq(np.column_stack([kn, mn]), cv, rcond=None)[0]
        a, b = float(coef[0]), float(coef[1])
    # refit on the entries of the rows that agree
    bad = np.abs(cv - a * kn - b * mn) > 1e-8 * scale
    out = np.union1d(rows[bad], cols[bad])
    keep = ~(np.isin(rows, out) | np.isin(cols, out))
    if keep.sum() >= 2:
        coef = np.linalg.lstsq(np.column_stack([kn[keep], mn[keep]]), cv[keep], rcond=None)[0]
        a, b = float(coef[0]), float(coef[1])
    a, b = a / sk, b / sm
    if abs(b) * sm <= 1e-13 * scale:
        b = 0.0
    if abs(a) * sk <= 1e-13 * scale:
        a = 0.0
    Rm = (C - a * K - b * M).tocoo()
    big = np.abs(Rm.data) > 1e-12 * scale
    S = np.union1d(Rm.row[big], Rm.col[big]).astype(np.int64)
    Rs = np.asarray((C - a * K - b * M).tocsr()[S][:, S].todense()) if S.size else np.zeros((0, 0))
    return float(a), float(b), S, 0.5 * (Rs + Rs.T)


def reduce_dynamics(model: Model, omega: float, *, modal_cutoff, n_modes,
                    steps_per_period) -> ReducedDynamics:
    """Reduce the free structure onto the contact DOFs (see module docstring).

    Node-to-node pairs are reduced in their relative coordinates ``U = P U'``
    (:func:`fretwear.model.interfaces.relative_model`); the returned basis maps the reduced
    coordinates to the physical free DOFs (``P`` applied), so loads, initial states and
    observed points need nothing else."""
    check_contact(model)
    model, P = relative_model(model)
    n = model.ndof
    free = model.free_dofs()
    nf = free.size
    pos = -np.ones(n, dtype=np.int64)
    pos[free] = np.arange(nf)
    K = submatrix(model.K.tocsr(), free, free)
    M = submatrix(model.M.tocsr(), free, free)
    C = sp.csr_matrix((nf, nf))
    if model.C is not None:
        C = C + submatrix(model.C.tocsr(), free, free)
    if model.D is not None:
        C = C + submatrix(model.D.tocsr(), free, free) / omega  # equivalent viscous at omega
    T = model.contact.local_transform(n).tocsr()[:, free]
    bnd = pos[np.asarray(model.contact.dofs).ravel()]
    nb = bnd.size
    mask = np.ones(nf, dtype=bool)
    mask[bnd] = False
    inner = np.flatnonzero(mask)
    ni = inner.size
    f = omega / (2.0 * np.pi)
    if modal_cutoff is None:
        f_cut = steps_per_period * f / CUTOFF_STEPS
    elif isinstance(modal_cutoff, str):
        if modal_cutoff != "all":
            raise InputError(f"modal_cutoff = {modal_cutoff!r}; expected a frequency [Hz], "
                             "None (default) or 'all'")
        f_cut = np.inf
    else:
        f_cut = positive(modal_cutoff, "modal_cutoff")
    if n_modes is not None:
        n_modes = count(n_modes, "n_modes", 0)
    info = {"n_dof_free": nf, "n_boundary": nb, "n_interior": ni}
    if ni == 0 or (np.isinf(f_cut) and n_modes is None):
        # no reduction: all free DOFs kept (boundary first)
        order = np.concatenate([bnd, inner])
        Phi = np.zeros((nf, nf))
        Phi[order, np.arange(nf)] = 1.0
        info.update(n_modes=ni, n_load_modes=0, cutoff_hz=np.inf, reduction="none")
    else:
        Kii = submatrix(K, inner, inner).tocsc()
        Kib = submatrix(K, inner, bnd)
        Mii = submatrix(M, inner, inner).tocsc()
        try:
            lu = spla.splu(Kii)
        except RuntimeError:
            raise InputError("the stiffness with the contact DOFs held is singular (a part of "
                             "the structure moves freely without touching the contact); use "
                             "modal_cutoff='all' or hold that part") from None
        Psi = -lu.solve(Kib.toarray())
        w2, Vm = fixed_interface_modes(Kii, Mii, 2 * np.pi * f_cut, n_modes)
        # static response of the interior to each load vector (contact DOFs held), with the
        # retained modes removed: the quasi-static contribution of the truncated modes
        extra = []
        for load in model.loads:
            Fi = np.asarray(load.vector, dtype=float)[free][inner]
            if not np.any(Fi):
                continue
            psi = lu.solve(Fi)
            nrm0 = math.sqrt(abs(psi @ (Kii @ psi))) or 1.0
            for _ in range(2):  # twice for round-off
                if Vm.shape[1]:
                    psi -= Vm @ (Vm.T @ (Mii @ psi))
                for v in extra:
                    psi -= v * (v @ (Mii @ psi))
            nrm = math.sqrt(abs(psi @ (Mii @ psi)))
            if math.sqrt(abs(psi @ (Kii @ psi))) > 1e-8 * nrm0 and nrm > 0.0:
                extra.append(psi / nrm)
        Pl = np.column_stack(extra) if extra else np.zeros((ni, 0))
        r = nb + Vm.shape[1] + Pl.shape[1]
        Phi = np.zeros((nf, r))
        Phi[bnd, np.arange(nb)] = 1.0
        Phi[np.ix_(inner, np.arange(nb))] = Psi
        Phi[np.ix_(inner, np.arange(nb, nb + Vm.shape[1]))] = Vm
        Phi[np.ix_(inner, np.arange(nb + Vm.shape[1], r))] = Pl
        info.update(n_modes=int(Vm.shape[1]), n_load_modes=int(Pl.shape[1]), cutoff_hz=f_cut,
                    reduction="craig-bampton",
                    highest_mode_hz=float(np.sqrt(max(w2[-1], 0.0)) / (2 * np.pi))
                    if w2.size else 0.0)
    Kr = Phi.T @ (K @ Phi)
    Mr = Phi.T @ (M @ Phi)
    Cr = Phi.T @ (C @ Phi)
    Kr = 0.5 * (Kr + Kr.T)
    Mr = 0.5 * (Mr + Mr.T)
    Cr = 0.5 * (Cr + Cr.T)
    diag = False
    Ul, Rl = np.zeros((0, 0)), np.zeros((0, 0))
    try:
        w2, V = sla.eigh(Kr, Mr)
    except np.linalg.LinAlgError:
        V = None
    if V is not None:
        basis = Phi @ V
        Cm = V.T @ Cr @ V
        Cm = 0.5 * (Cm + Cm.T)
        big = np.abs(Cm).max() if Cm.size else 0.0
        # damping in modal coordinates: a w^2 + b + low rank (undamped springs), if it fits
        a, b, S, Rs = damping_split(K, M, C)
        Ul = basis[S].T if S.size else np.zeros((basis.shape[1], 0))
        approx = a * np.diag(w2) + b * np.eye(w2.size) + Ul @ Rs @ Ul.T
        fits = big == 0.0 or np.abs(Cm - approx).max() <= 1e-9 * big
        if fits and S.size <= max(8, basis.shape[1] // 4):
            diag = True
            Kred, Mred, Cred, Rl = w2.copy(), np.ones_like(w2), a * w2 + b, Rs
            info["damping"] = {"a_K": a, "b_M": b, "low_rank": int(S.size)}
        else:
            Kred, Mred, Cred = np.diag(w2), np.eye(w2.size), Cm
            Ul = np.zeros((0, 0))
        info["highest_frequency_hz"] = float(np.sqrt(max(w2.max(), 0.0)) / (2 * np.pi))
    else:
        basis, Kred, Mred, Cred = Phi, Kr, Mr, Cr
    info["r"] = int(basis.shape[1])
    info["diagonal"] = diag
    Tx = np.asarray(T @ basis)  # the contact-local (relative) displacements
    if P is not None:  # back to the physical free DOFs: U_free = P_ff U'_free
        basis = np.asarray(P.tocsr()[free][:, free] @ basis)
    names, slices, rows = [], [], []
    start = 0
    for p in model.observed:
        d = np.asarray(p.dofs, dtype=np.int64).ravel()
        rr = np.zeros((d.size, basis.shape[1]))
        ok = pos[d] >= 0
        rr[ok] = basis[pos[d[ok]]]
        slices.append(slice(start, start + d.size))
        start += d.size
        rows.append(rr)
        names.append(p.name)
    obs = np.vstack(rows) if rows else np.zeros((0, basis.shape[1]))
    if not diag:
        Ul, Rl = np.zeros((basis.shape[1], 0)), np.zeros((0, 0))
    return ReducedDynamics(free=free, basis=basis, K=Kred, M=Mred, C=Cred,
                           U=np.ascontiguousarray(Ul), R=np.ascontiguousarray(Rl), diag=diag,
                           modal=V is not None, Tx=Tx, obs=obs, obs_names=names,
                           obs_slices=slices, info=info)
