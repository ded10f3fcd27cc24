"""Linear analyses of a model with a linearised contact interface: normal modes and FRFs.

The frictional interface is replaced by one of three linear limits (:data:`INTERFACES`):

* ``"free"``: no contact constraint at all;
* ``"sliding"``: frictionless bilateral contact: the normal displacement of every contact node
  is held (``n . u = 0``), its tangential displacement is free;
* ``"stuck"``: every contact DOF is held (full stick, no separation).

Constraints are written in the contact-local frames (row 0 the normal, see
:mod:`fretwear.model.core`), exactly, for any orientation of the frame: the displacement is
written ``U = T q`` where ``q`` equals ``U`` except at the contact nodes, where it holds the
local components ``[u_N, u_T1, (u_T2)]`` at the positions of that node's global DOFs: local
component ``k`` sits at the global DOF of the axis that frame row ``k`` is closest to
(:func:`local_positions`), ``q[pos[p, k]] = frame[p, k] . U[dofs[p]]``. A held component is a
removed coordinate of ``q``. For axis-aligned frames ``T`` is a signed permutation and the
held coordinates are the global DOFs along the held directions.

Damping enters exactly as in :func:`fretwear.hb.reduce.dynamic_stiffness` (hysteretic ``D`` and
viscous ``C``: ``Z = K + i D - w^2 M + i w C``); the FRF is that of the harmonic ``n = 1``
part of the model loads, with the complex amplitude convention ``u(t) = Re U e^{i w t}``.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from fretwear.errors import InputError
from fretwear.hb.reduce import condenser_for
from fretwear.limits import RANGES
from fretwear.model.checks import model_argument
from fretwear.model.core import Model
from fretwear.model.interfaces import pair_transform
from fretwear.resources import require_memory
from fretwear.threads import limited
from fretwear.validate import instance, number, reals, whole

INTERFACES = ("free", "sliding", "stuck")
FRF_METHODS = ("direct", "condensed", "projected")
_AXES = {"x": 0, "y": 1, "z": 2}
#: constrained systems with at most this many unknowns are solved by dense ``eigh``
DENSE_EIG_LIMIT = 600


# --- constraints --------------------------------------------------------------------------
def _check_interface(interface: str) -> str:
    if interface not in INTERFACES:
        raise InputError(f"unknown interface {interface!r}: expected one of {INTERFACES}")
    return interface


def _check_contact(model: Model) -> None:
    """The contact DOFs must be distinct, not fixed, with orthonormal frames."""
    c = model.contact
    dofs = np.asarray(c.dofs, dtype=np.int64).reshape(-1)
    if np.unique(dofs).size != dofs.size:
        raise InputError("contact DOFs must be distinct: a DOF appears in two contact nodes")
    if dofs.size and (dofs.min() < 0 or dofs.max() >= model.ndof):
        raise InputError(f"contact DOFs must lie in 0..{model.ndof - 1}")
    if np.intersect1d(dofs, np.asarray(model.fixed_dofs, dtype=np.int64)).size:
        raise InputError("contact DOFs cannot also be fixed (Dirichlet) DOFs")
    frame = np.asarray(c.frame, dtype=float)
    gram = frame @ np.swapaxes(frame, 1, 2)
    if frame.size and not np.allclose(gram, np.eye(c.dim), atol=1e-10):
        raise InputError("each contact frame must have orthonormal rows [n, t1(, t2)]")


def local_positions(model: Model) -> np.ndarray:
    """Where each contact-local component lives in ``q`` (see module docstring).

    Returns
    -------
    (nc, d) int array ``pos``: local component ``k`` of contact node ``p`` is ``q[pos[p, k]]``.
    ``pos[p]`` is a permutation of ``dofs[p]`` maximising ``sum_k |frame[p, k, perm[k]]|``, so
    that an axis-aligned normal sits at the global DOF along that axis (e.g. a normal
    ``(0, -1)`` at the node's y DOF).
    """
    c = model.contact
    frame = np.abs(np.asarray(c.frame, dtype=float))
    d = c.dim
    perms = np.array(list(itertools.permutations(range(d))), dtype=np.int64)  # (np, d)
    scores = frame[:, np.arange(d)[None, :], perms].sum(axis=-1)  # (nc, np)
    best = perms[np.argmax(scores, axis=1)]  # (nc, d)
    return np.take_along_axis(np.asarray(c.dofs, dtype=np.int64), best, axis=1)


def local_transform(model: Model) -> sp.csr_matrix:
    """``T`` (ndof, ndof) with ``U = T q`` (see module docstring).

    Returns
    -------
    T : sparse (ndof, ndof); ``q`` holds the contact-local components at the positions of
        the contact nodes' global DOFs and the global components elsewhere. Without
        node-to-node pairs ``T`` is orthogonal (``q = T.T @ U``); a pair's local components
        are those of the relative displacement ``U_a - U_b``, and ``T = P T_frame`` with the
        pair transform ``P`` of :func:`fretwear.model.interfaces.pair_transform`.
    """
    _check_contact(model)
    c = model.contact
    nc, d = c.dofs.shape
    other = np.setdiff1d(np.arange(model.ndof), c.dofs.reshape(-1))
    pos = local_positions(model)
    # U[dofs[p, a]] = sum_k frame[p, k, a] q[pos[p, k]]
    rows = np.broadcast_to(c.dofs[:, None, :], (nc, d, d)).reshape(-1)  # a varies fastest
    cols = np.broadcast_to(pos[:, :, None], (nc, d, d)).reshape(-1)  # k
    vals = np.asarray(c.frame, dtype=float).reshape(-1)  # frame[p, k, a]
    rows = np.concatenate([rows, other])
    cols = np.concatenate([cols, other])
    vals = np.concatenate([vals, np.ones(other.size)])
    T = sp.csr_matrix((vals, (rows, cols)), shape=(model.ndof, model.ndof))
    P = pair_transform(c, model.ndof)  # node-to-node pairs: U = P U', U'_a = U_a - U_b
    return T if P is None else (P @ T).tocsr()


def _held_local(model: Model, interface: str) -> np.ndarray:
    """(nc, d) bool: which contact-local components the interface holds."""
    nc, d = model.contact.dofs.shape
    held = np.zeros((nc, d), dtype=bool)
    if interface == "sliding":
        held[:, 0] = True
    elif interface == "stuck":
        held[:] = True
    return held


def constrained_dofs(model: Model, interface: str) -> np.ndarray:
    """Coordinates held for ``interface``, including the model's fixed DOFs.

    Parameters
    ----------
    model : the model.
    interface : one of :data:`INTERFACES`.

    Returns
    -------
    (nh,) sorted int array of indices into ``q = T.T @ U`` (:func:`local_transform`): the
    global DOF numbers, where at a contact node ``pos[p, k]`` (:func:`local_positions`)
    stands for its local component ``k`` (0 = normal). For axis-aligned frames these are the
    plain global DOFs along the held directions; for a tilted frame, holding ``pos[p, 0]``
    means the exact constraint ``n . u = 0``.
    """
    _check_interface(interface)
    _check_contact(model)
    held = local_positions(model)[_held_local(model, interface)]
    fixed = np.asarray(model.fixed_dofs, dtype=np.int64)
    return np.unique(np.concatenate([fixed, held.astype(np.int64)]))


def _reduced_basis(model: Model, interface: str):
    """``(T, Tf, free)``: ``U = Tf @ q_f`` spans the displacements allowed by the interface."""
    T = local_transform(model).tocsc()
    held = constrained_dofs(model, interface)
    free = np.setdiff1d(np.arange(model.ndof), held)
    return T, T[:, free], free


# --- modes --------------------------------------------------------------------------------
@dataclass
class ModesResult:
    """Normal modes of the undamped structure with a linear interface.

    Attributes
    ----------
    interface : one of :data:`INTERFACES`.
    frequency_hz : (nm,) natural frequencies [Hz], ascending; rigid-body modes at ~0.
    shapes : (nm, ndof) mode shapes in the structure's axes, mass-normalised
        (``phi^T M phi = 1`` [1/kg], so shapes are in [kg^-1/2]).
    observed : name -> (nm, d) shapes at each observed point.
    """

    interface: str
    frequency_hz: np.ndarray
    shapes: np.ndarray
    observed: dict


def _shift(K: sp.spmatrix, M: sp.spmatrix) -> float:
    """A small negative shift [rad^2/s^2] that makes ``K - sigma M`` positive definite when
    ``K`` only has rigid-body null vectors with mass."""
    tm = abs(M.diagonal()).sum()
    tk = abs(K.diagonal()).sum()
    return -1e-8 * (tk / tm if tm > 0 else 1.0)


def _eig_dense(K, M, sigma: float):
    """All finite eigenpairs of ``K x = lam M x`` via ``M x = nu (K - sigma M) x``."""
    A = (K - sigma * M).toarray()
    try:
        nu, X = sla.eigh(M.toarray(), A)
    except np.linalg.LinAlgError as exc:
        raise InputError(
            "the constrained structure has a motion with neither stiffness nor mass "
            "(e.g. a massless DOF with no spring): add stiffness, mass or fixed DOFs"
        ) from exc
    keep = nu > 1e-12 * max(nu.max(), 0.0)
    nu, X = nu[keep], X[:, keep]
    return sigma + 1.0 / nu, X / np.sqrt(nu)


def _eig_sparse(K, M, k: int, sigma: float):
    """The ``k`` eigenpairs nearest ``sigma`` by shift-invert Lanczos (M may be singular)."""
    try:
        # a fixed start vector (SciPy's default draws fresh entropy: degenerate modes would
        # differ by rounding from run to run)
        lam, X = spla.eigsh(K, k=k, M=M, sigma=sigma, which="LM",
                            v0=np.random.default_rng(0).standard_normal(K.shape[0]))
    except RuntimeError as exc:  # singular K - sigma M
        raise InputError(
            "the constrained structure has a motion with neither stiffness nor mass "
            "(e.g. a massless DOF with no spring): add stiffness, mass or fixed DOFs"
        ) from exc
    return lam, X


def _check_eig(n: int, k: int, dense: bool) -> None:
    """Refuse (one InputError with the estimate and the machine's memory) ``k`` modes of
    ``n`` DOFs that cannot fit: densely, the two matrices, the eigenvectors and LAPACK's
    work arrays (``n x n`` each); by Lanczos, its basis (``2 k + 1`` vectors of ``n``), the
    ``k`` modes and its dense ``(2 k + 1)^2`` work arrays."""
    if dense:
        require_memory(8.0 * 5 * n * n, f"the dense eigenproblem of {n:,} DOFs (every mode: "
                       "n_modes or f_max reach the model's size)")
    else:
        require_memory(8.0 * n * (3 * k + 2) + 24.0 * (2 * k + 1) ** 2,
                       f"{k:,} modes of {n:,} DOFs")


def _lowest_modes(K, M, n_modes: int, lam_max: float | None):
    """Lowest eigenpairs ``(lam, X)`` of the pencil; all below ``lam_max`` when given."""
    n = K.shape[0]
    sigma = _shift(K, M)
    if n <= DENSE_EIG_LIMIT:
        lam, X = _eig_dense(K, M, sigma)
    else:
        k = max(1, n_modes)
        while True:
            if k >= n - 1:
                _check_eig(n, n, True)
                lam, X = _eig_dense(K, M, sigma)
                break
            _check_eig(n, k, False)
            lam, X = _eig_sparse(K, M, k, sigma)
            if lam_max is None or lam.max() > lam_max:
                break
            k = min(2 * k, n - 1)
    # drop spurious pairs of a singular M (infinite eigenvalues: no modal mass)
    mm = np.einsum("ij,ij->j", X, M @ X)
    ok = np.isfinite(lam) & (mm > 1e-12 * mm.max(initial=0.0))
    lam, X = lam[ok], X[:, ok]
    order = np.argsort(lam)
    lam, X = lam[order], X[:, order]
    if lam_max is None:
        return lam[:n_modes], X[:, :n_modes]
    keep = lam <= lam_max
    return lam[keep], X[:, keep]


def _normalise(X: np.ndarray, M) -> np.ndarray:
    """Columns scaled to unit modal mass; sign chosen so the largest entry is positive."""
    X = X / np.sqrt(np.einsum("ij,ij->j", X, M @ X))
    big = X[np.argmax(np.abs(X), axis=0), np.arange(X.shape[1])]
    return X * np.where(big < 0, -1.0, 1.0)


@model_argument
@limited
def modes(model: Model, n_modes: int = 10, *, interface: str = "sliding",
          f_max: float | None = None) -> ModesResult:
    """Normal modes of the undamped structure with the given linear interface.

    Solves ``K phi = w^2 M phi`` on the displacements allowed by ``interface`` (exact
    constraints in the contact-local frames). Shift-invert with a small negative shift: rigid
    body modes are found (at ~0 Hz) and a singular ``M`` (massless DOFs) is allowed. Small
    systems (<= :data:`DENSE_EIG_LIMIT` unknowns) use a dense symmetric solver.

    Parameters
    ----------
    model : the model (``K``, ``M``; damping is ignored).
    n_modes : number of lowest modes returned (ignored when ``f_max`` is given).
    interface : one of :data:`INTERFACES`.
    f_max : if given, every mode with frequency <= ``f_max`` [Hz] is returned.

    Returns
    -------
    ModesResult: ``interface``, ``frequency_hz`` (nm,) natural frequencies [Hz], ``shapes``
    (nm, ndof) mass-normalised mode shapes (a linear computation: no ``success`` to report).
    """
    instance(model, Model, "model", "a fretwear Model (fretwear.from_mesh, "
             "fretwear.from_matrices)")
    _check_interface(interface)
    if f_max is None:
        whole(n_modes, "n_modes", low=1)
    else:
        number(f_max, "f_max", low=0.0, open_low=True, high=RANGES["frequency"][1], unit="Hz")
    _, Tf, _ = _reduced_basis(model, interface)
    if Tf.shape[1] == 0:
        raise InputError(f"interface {interface!r} holds every DOF: the structure cannot move")
    K = (Tf.T @ model.K @ Tf).tocsc()
    M = (Tf.T @ model.M @ Tf).tocsc()
    if not np.any(M.diagonal() > 0):
        raise InputError(f"the model has no mass on the DOFs left free by the {interface!r} "
                         "interface: modes need a mass matrix (material density > 0)")
    K, M = 0.5 * (K + K.T), 0.5 * (M + M.T)
    lam_max = None if f_max is None else (2.0 * np.pi * f_max) ** 2
    lam, X = _lowest_modes(K.tocsc(), M.tocsc(), n_modes, lam_max)
    X = _normalise(X, M)
    # Rayleigh quotients: second-order accurate in the shapes, they remove the loss of
    # relative accuracy of 1/nu - |sigma| for modes far from the shift
    lam = np.einsum("ij,ij->j", X, K @ X)
    shapes = np.asarray((Tf @ X).T)
    freq = np.sqrt(np.clip(lam, 0.0, None)) / (2.0 * np.pi)
    obs = {p.name: shapes[:, np.asarray(p.dofs, dtype=np.int64)] for p in model.observed}
    return ModesResult(interface, freq, shapes, obs)


# --- FRF ----------------------------------------------------------------------------------
@dataclass
class FRFResult:
    """Forced response to the harmonic (n = 1) part of the loads, ``u(t) = Re U e^{i w t}``.

    Attributes
    ----------
    interface : one of :data:`INTERFACES`.
    frequency_hz : (nf,) excitation frequencies [Hz].
    observed : name -> (nf, d) complex displacement amplitudes [m] in the structure's axes.
    contact : (nf, nc, d) complex contact-local displacement amplitudes [m] (0 where held).
    reaction : (nf, nc, d) complex contact-local forces [N] the structure exerts on the
        obstacle on the held components (``lambda`` of :mod:`fretwear.model.core`, positive
        in compression); 0 on free components.
    method : ``"direct"`` or ``"condensed"``.
    """

    interface: str
    frequency_hz: np.ndarray
    observed: dict
    contact: np.ndarray
    reaction: np.ndarray
    method: str = "direct"


def _harmonic_load(model: Model) -> np.ndarray:
    F = model.load_harmonics(1)[1]
    if not np.any(F):
        raise InputError(
            "the model has no harmonic load: an FRF needs a load with a harmonic n = 1 "
            "part (waveform 'cos', 'sin', 'triangle' or 'fourier' with n = 1)"
        )
    return F


def _check_frequencies(frequencies_hz) -> np.ndarray:
    f = np.atleast_1d(reals(frequencies_hz, "frequencies_hz", low=0.0, open_low=True))
    if f.ndim != 1:
        raise InputError("frequencies_hz must be a non-empty 1D array of positive values [Hz]")
    return f


def _singular_message(interface: str, f_hz: float) -> str:
    return (
        f"the {interface!r} structure is singular at {f_hz:.6g} Hz: an undamped "
        "eigenfrequency, or a rigid-body motion (add damping, springs or fixed DOFs)"
    )


def _solve(Z, rhs, f_hz: float, interface: str):
    """Sparse complex solve with a clear message at an undamped resonance."""
    try:
        lu = spla.splu(sp.csc_matrix(Z, dtype=complex), permc_spec="MMD_AT_PLUS_A",
                       options={"SymmetricMode": True})  # Z is (complex) symmetric
        x = lu.solve(np.asarray(rhs, dtype=complex))
    except RuntimeError as exc:
        x = None
        cause = exc
    else:
        cause = None
    if x is None or not np.all(np.isfinite(x)):
        raise InputError(_singular_message(interface, f_hz)) from cause
    return x


def _solve_dense(Z: np.ndarray, rhs: np.ndarray, f_hz: float, interface: str):
    """Dense complex solve of the reduced system, same message as :func:`_solve`."""
    try:
        x = np.linalg.solve(Z, rhs)
    except np.linalg.LinAlgError:
        x = None
    if x is None or not np.all(np.isfinite(x)):
        raise InputError(_singular_message(interface, f_hz))
    return x


def _on_pattern(A: sp.spmatrix, pattern: sp.csc_matrix) -> np.ndarray:
    """Entries of ``A`` as a data array aligned with the canonical CSC ``pattern``."""
    A = sp.coo_matrix(A)
    A.eliminate_zeros()  # explicit zeros may be missing from the pattern
    n = pattern.shape[0]
    cols = np.repeat(np.arange(pattern.shape[1]), np.diff(pattern.indptr))
    keys = cols.astype(np.int64) * n + pattern.indices
    pos = np.searchsorted(keys, A.col.astype(np.int64) * n + A.row)
    out = np.zeros(keys.size, dtype=float)
    np.add.at(out, pos, A.data)
    return out


class _Pencil:
    """``Z(w) = K + i D - w^2 M + i w C`` (as :func:`fretwear.hb.reduce.dynamic_stiffness` at
    ``n = 1``) of a sub-block, assembled per frequency on a fixed sparsity pattern."""

    def __init__(self, mats: dict):
        present = {k: sp.csc_matrix(A) for k, A in mats.items() if A is not None}
        pattern = sum(abs(A) for A in present.values()).tocsc()
        pattern.sum_duplicates()
        pattern.sort_indices()
        self.indices, self.indptr, self.shape = pattern.indices, pattern.indptr, pattern.shape
        zero = np.zeros(pattern.nnz)
        self.data = {k: _on_pattern(present[k], pattern) if k in present else zero
                     for k in "KMDC"}

    def __call__(self, w: float) -> sp.csc_matrix:
        d = self.data
        z = d["K"] - (w * w) * d["M"] + 1j * (d["D"] + w * d["C"])
        return sp.csc_matrix((z, self.indices, self.indptr), shape=self.shape)


#: backward error ``|Z(w) q - F| / (|K q| + |w^2 M q| + |D q| + |w C q| + |F|)`` that the
#: projected FRF meets at every frequency (``method="projected"``): the residual relative to
#: the size of the terms it is made of (rounding alone leaves about 1e-16); where the
#: projection cannot reach it the frequency is solved directly
PROJECTED_TOL = 1e-8


def _direct_solutions(ff: _Pencil, Ff: np.ndarray, freqs: np.ndarray, interface: str):
    """(nf, n) solutions of ``Z_ff(w) q = F_f``, one sparse factorisation per frequency."""
    return np.array([_solve(ff(2.0 * np.pi * f), Ff, f, interface) for f in freqs])


def _orthonormal_extension(V: np.ndarray, X: np.ndarray) -> np.ndarray:
    """``V`` (n, r) with orthonormal columns, extended by the parts of the columns of ``X``
    not already in its span (Gram-Schmidt twice; a column whose new part is below ``1e-14``
    of its norm is dropped)."""
    for x in X.T:
        norm = np.linalg.norm(x)
        if norm == 0.0:
            continue
        for _ in range(2):
            x = x - V @ (V.T @ x)
        if np.linalg.norm(x) > 1e-14 * norm:
            V = np.column_stack([V, x / np.linalg.norm(x)])
    return V


def _small_solve(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``A^-1 b`` of a projected system, NaN where ``A`` is singular (the frequency is then
    solved directly, which says why it is singular)."""
    try:
        return np.linalg.solve(A, b)
    except np.linalg.LinAlgError:
        return np.full(b.shape, np.nan, dtype=complex)


def _projected_solutions(ff: _Pencil, Ff: np.ndarray, freqs: np.ndarray, interface: str,
                         tol: float = PROJECTED_TOL):
    """(nf, n) solutions of ``Z_ff(w) q = F_f`` by projection on the exact solutions at a
    few frequencies (a rational Krylov, or reduced-basis, space chosen greedily).

    The space starts with the solutions at the two ends and the middle of the band; the
    system is projected on it (real basis ``V`` spanning the real and imaginary parts,
    ``V^T Z(w) V y = V^T F``) and solved at every frequency, and the true residual
    ``Z(w) V y - F`` of each is evaluated exactly (it is ``B c(w)`` with
    ``B = [K V, M V, D V, C V, F]``: its norm is that of ``R c(w)``, ``B = Q R``), as a
    backward error: relative to the sum of the norms of its terms (:data:`PROJECTED_TOL`).
    The frequency not yet in the space with the largest one adds its exact solution, until
    every one is below ``tol``. The projected system reproduces the exact solution wherever
    it lies in the space (at every added frequency), so the error is that of the residual
    test; where the space stops growing, or after ``nf // 4`` added frequencies (direct
    solves would then cost about as much), the frequencies still above ``tol`` are solved
    directly. Costs one sparse factorisation per added frequency (a few per resonance in
    the band) instead of one per frequency."""
    nf = freqs.size
    if nf <= 3:
        return _direct_solutions(ff, Ff, freqs, interface)
    shape = ff.shape
    mats = {k: sp.csc_matrix((v, ff.indices, ff.indptr), shape=shape)
            for k, v in ff.data.items()}
    w = 2.0 * np.pi * freqs
    fnorm = np.linalg.norm(Ff)
    if fnorm == 0.0:
        return np.zeros((nf, shape[0]), dtype=complex)
    V = np.zeros((shape[0], 0))
    added: list[int] = []
    todo = [0, nf // 2, nf - 1]
    Y = rel = None
    width = 0  # columns of V before the last added frequencies
    while todo:
        for i in todo:
            q = _solve(ff(w[i]), Ff, freqs[i], interface)
            V = _orthonormal_extension(V, np.column_stack([q.real, q.imag]))
            added.append(i)
        todo = []
        prod = {k: mats[k] @ V for k in "KMDC"}
        red = {k: V.T @ prod[k] for k in "KMDC"}
        Fr = V.T @ Ff
        Y = np.array([_small_solve(red["K"] - wi * wi * red["M"]
                                   + 1j * (red["D"] + wi * red["C"]), Fr) for wi in w])
        _, R = np.linalg.qr(np.column_stack([prod[k] for k in "KMDC"] + [Ff]))
        r = V.shape[1]
        terms = [Y, -(w * w)[:, None] * Y, 1j * Y, 1j * w[:, None] * Y]
        c = np.hstack([*terms, -np.ones((nf, 1))])
        size = fnorm + sum(np.linalg.norm(t @ R[:, k * r:(k + 1) * r].T, axis=1)
                           for k, t in enumerate(terms))
        rel = np.linalg.norm(c @ R.T, axis=1) / size
        rel[~np.isfinite(rel)] = np.inf  # a singular projected system: solve it directly
        left = rel.copy()
        left[added] = -np.inf
        worst = int(np.argmax(left))
        if left[worst] > tol and V.shape[1] > width and len(added) < max(nf // 4, 3):
            todo = [worst]
        width = V.shape[1]
    Q = Y @ V.T
    for i in np.flatnonzero(rel > tol):  # the space stopped improving there
        Q[i] = _solve(ff(w[i]), Ff, freqs[i], interface)
    return Q


def _frf_direct(model: Model, freqs: np.ndarray, interface: str, F: np.ndarray,
                projected: bool = False):
    T, Tf, free = _reduced_basis(model, interface)
    pos = local_positions(model)
    held = _held_local(model, interface)
    mats = {"K": model.K, "M": model.M, "D": model.D, "C": model.C}
    # Z_ff q_f = T_f^T F on the allowed coordinates; T_c^T (F - Z T_f q_f) on the contact
    # coordinates gives the constraint forces (lambda), T_o T_f q_f the observed DOFs
    Tc = T[:, pos.reshape(-1)]
    ff = _Pencil({k: None if A is None else Tf.T @ A @ Tf for k, A in mats.items()})
    cf = _Pencil({k: None if A is None else Tc.T @ A @ Tf for k, A in mats.items()})
    obs = np.concatenate([np.asarray(p.dofs, dtype=np.int64) for p in model.observed]
                         or [np.zeros(0, dtype=np.int64)])
    To = Tf[obs]
    Ff, Fc = Tf.T @ F, Tc.T @ F
    fpos = np.full(model.ndof, -1)
    fpos[free] = np.arange(free.size)
    cfree = fpos[pos.reshape(-1)]  # index of each contact coordinate among the free ones
    Q = (_projected_solutions if projected else _direct_solutions)(ff, Ff, freqs, interface)
    Uo, con, rea = [], [], []
    for f, qf in zip(freqs, Q, strict=True):
        w = 2.0 * np.pi * f
        qc = np.where(cfree >= 0, qf[np.maximum(cfree, 0)], 0.0)
        lam = np.where(held.reshape(-1), Fc - cf(w) @ qf, 0.0)
        Uo.append(To @ qf)
        con.append(qc.reshape(pos.shape))
        rea.append(lam.reshape(pos.shape))
    Uo = np.array(Uo).reshape(freqs.size, -1)
    return _split_observed(model, Uo), np.array(con), np.array(rea)


def _split_observed(model: Model, Uo: np.ndarray) -> dict:
    """name -> (nf, d) columns of ``Uo`` (nf, no) in the order of ``model.observed``."""
    observed, start = {}, 0
    for p in model.observed:
        n = len(p.dofs)
        observed[p.name] = Uo[:, start : start + n]
        start += n
    return observed


def _frf_condensed(model: Model, freqs: np.ndarray, interface: str, condenser=None):
    cond = condenser_for(model, condenser)  # one for every frequency
    nc, d = model.contact.dofs.shape
    held = _held_local(model, interface).reshape(-1)
    keep = np.flatnonzero(~held)
    obs, con, rea = [], [], []
    for f in freqs:
        red = cond.reduced(2 * np.pi * f, [1], False, f)  # = condense(model, f, [1])
        Z, Fr = red.Z[0], red.F[0]
        u = np.zeros(nc * d, dtype=complex)
        if keep.size:
            u[keep] = _solve_dense(Z[np.ix_(keep, keep)], Fr[keep], f, interface)
        lam = np.where(held, Fr - Z @ u, 0.0)  # Z_r u + lambda = F_r
        obs.append(red.obs_A[0] @ u + red.obs_b[0])
        con.append(u.reshape(nc, d))
        rea.append(lam.reshape(nc, d))
    Uo = np.array(obs).reshape(freqs.size, -1)
    return _split_observed(model, Uo), np.array(con), np.array(rea)


@model_argument
@limited
def frf(model: Model, frequencies_hz, *, interface: str = "sliding",
        method: str = "direct", condenser=None) -> FRFResult:
    """Frequency response to the harmonic (n = 1) part of the model loads.

    Parameters
    ----------
    model : the model; its loads must have a harmonic ``n = 1`` part.
    frequencies_hz : (nf,) excitation frequencies [Hz] (> 0).
    interface : one of :data:`INTERFACES`.
    method : ``"direct"`` (sparse complex solve of the whole constrained model per
        frequency), ``"condensed"`` (:func:`fretwear.hb.reduce.condense` at harmonic 1, then
        the constraint applied to the reduced contact-local coordinates), both exact, agreeing
        to rounding; or ``"projected"``, for fine frequency grids: the exact solutions at a
        few frequencies chosen greedily span a space on which the system is projected, until
        the relative residual ``|Z q - F| / |F|`` is below :data:`PROJECTED_TOL` at every
        frequency (one sparse solve per chosen frequency, a few per resonance; see
        ``_projected_solutions``).
    condenser : with ``method="condensed"``, the condenser of ``model``
        (:func:`fretwear.hb.reduce.exact_condenser` or
        :func:`fretwear.hb.modal.modal_condenser`); None: a new exact one for the call. The
        other methods solve the whole model and take none.

    Returns
    -------
    FRFResult: ``interface``, ``frequency_hz`` (nf,) [Hz], ``observed``: name -> (nf, d)
    complex displacement amplitudes [m], contact displacements [m] and reactions [N].
    """
    instance(model, Model, "model", "a fretwear Model (fretwear.from_mesh, "
             "fretwear.from_matrices)")
    _check_interface(interface)
    if method not in FRF_METHODS:
        raise InputError(f"unknown FRF method {method!r}: expected one of {FRF_METHODS}")
    freqs = _check_frequencies(frequencies_hz)
    check_frf_size(model, freqs.size, method)
    F = _harmonic_load(model)
    _check_contact(model)
    if method in ("direct", "projected"):
        observed, con, rea = _frf_direct(model, freqs, interface, F,
                                         projected=method == "projected")
    else:
        observed, con, rea = _frf_condensed(model, freqs, interface, condenser)
    return FRFResult(interface, freqs, observed, con, rea, method)


def check_frf_size(model: Model, n_frequencies: int, method: str = "direct") -> None:
    """Refuse an FRF whose responses cannot fit in memory, before anything is allocated: at
    every frequency, complex values on the free DOFs (``"direct"``, ``"projected"``), the
    observed DOFs, the contact displacements and reactions."""
    per_f = (model.ndof if method != "condensed" else 0) + 2 * model.contact.dofs.size \
        + sum(len(p.dofs) for p in model.observed)
    require_memory(16.0 * n_frequencies * per_f, f"an FRF of {model.ndof:,} DOFs at "
                   f"{n_frequencies:,} frequencies")


def frequency_grid(f_min: float, f_max: float, n: int, spacing: str = "log") -> np.ndarray:
    """``n`` frequencies [Hz] from ``f_min`` to ``f_max`` (both included).

    Parameters
    ----------
    f_min, f_max : band limits [Hz], ``0 < f_min < f_max``.
    n : number of points (>= 2).
    spacing : ``"log"`` (geometric) or ``"linear"``.
    """
    if spacing not in ("log", "linear"):
        raise InputError(f"unknown spacing {spacing!r}: expected 'log' or 'linear'")
    if not (0 < f_min < f_max) or not np.isfinite(f_max):
        raise InputError(f"expected 0 < f_min < f_max, got f_min = {f_min}, f_max = {f_max}")
    if int(n) < 2:
        raise InputError(f"a frequency grid needs n >= 2 points, got {n}")
    require_memory(8.0 * int(n), f"a grid of {int(n):,} frequencies")
    if spacing == "log":
        return np.geomspace(f_min, f_max, int(n))
    return np.linspace(f_min, f_max, int(n))


def _axis_index(axis) -> int:
    if isinstance(axis, str):
        if axis.lower() not in _AXES:
            raise InputError(f"unknown axis {axis!r}: expected 'x', 'y', 'z' or an index")
        return _AXES[axis.lower()]
    return int(axis)


def count_resonances(frf_result: FRFResult, point: str, axis, *,
                     prominence: float = 0.5) -> tuple[int, np.ndarray]:
    """Resonance peaks of ``|U|`` of one observed component over the computed band.

    A peak is a local maximum of ``log10 |U|`` whose topographic prominence is at least
    ``prominence`` decades (:func:`scipy.signal.find_peaks`); this rejects ripples and the
    shoulders of neighbouring peaks. A peak at either end of the band is not counted. The
    frequency grid must resolve the peaks (spacing well below the half-power bandwidth
    ``eta f`` is not needed, but a peak falling between two grid points loses height).

    Parameters
    ----------
    frf_result : an :class:`FRFResult`.
    point : name of an observed point.
    axis : ``"x"``, ``"y"``, ``"z"`` or a component index.
    prominence : minimum prominence [decades of amplitude].

    Returns
    -------
    (n, frequencies) : the number of peaks and their grid frequencies [Hz].
    """
    if point not in frf_result.observed:
        raise InputError(
            f"no observed point {point!r} in the FRF; it has {list(frf_result.observed)}"
        )
    U = frf_result.observed[point]
    k = _axis_index(axis)
    if not 0 <= k < U.shape[1]:
        raise InputError(f"axis {axis!r} out of range for a point with {U.shape[1]} components")
    amp = np.abs(U[:, k])
    logamp = np.log10(np.maximum(amp, np.finfo(float).tiny))
    from scipy.signal import find_peaks  # lazy: scipy.signal is slow to import

    peaks, _ = find_peaks(logamp, prominence=prominence)
    return int(peaks.size), frf_result.frequency_hz[peaks]
