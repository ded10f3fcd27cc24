"""The structure's dynamic stiffness at any complex Laplace variable, condensed on the contact.

The harmonic balance needs the condensed dynamic stiffness ``Z_r(n w)`` at the kept harmonics
of one real frequency (eq. 18-19, :mod:`fretwear.hb.reduce`). Hill's method
(:mod:`fretwear.hb.stability`) needs it at ``lambda = s + i n w`` for a complex Floquet exponent
``s``, and the nonlinear modes (:mod:`fretwear.hb.nonlinear_modes`) with a negative
mass-proportional damping ``-xi M``. Both are the same Schur complement (eq. 19) of

    Z = K + a M + b C + c D

for coefficients ``(a, b, c)``: ``(lambda^2, lambda, +-i)`` for Hill's method (the hysteretic
``D`` keeps the sign of the harmonic it acts on, as in the balance; it is absent from harmonic
0, where the balance has ``Z_0 = K``), ``(-(n w)^2 - i n w xi, i n w, i)`` for a mode.

:class:`StructureDynamics` holds the structure in coordinates ``(x, q)``: ``x`` the contact
points the law acts on, ``q`` everything else. Without contact springs ``x = u_c`` are the
contact DOFs in their local frames and the interior is ``u_i = Psi u_c + V q``:

* a model with at most :data:`DENSE_INTERIOR_MAX` interior DOFs: ``Psi = -K_ii^-1 K_ic`` and
  ``V = I`` (``q`` the interior motion relative to the static shape): the transformation is
  one-to-one, so every ``Z_r(lambda)`` is exact;
* a model with a modal condenser (:func:`fretwear.hb.modal.modal_condenser`, passed as
  ``condenser``): its projected matrices (``V`` the fixed-interface modes kept and the
  loads' static responses), with the error that representation was checked for.

A contact spring joins the structure's contact DOF to a massless contact point
(:mod:`fretwear.hb.connectors`): the point is in ``x``, the structure's DOF moves to ``q``, so
that the blocks stay quadratic in ``lambda`` (Hill's quadratic problem) and the structure's
modes with the contact points held are those of ``(K_qq, M_qq)`` (the nonlinear modes' master
coordinates). The blocks are dense: ``Z_r(lambda) = Z^xx - Z^xq (Z^qq)^-1 Z^qx`` costs a
``q x q`` solve with ``m`` right-hand sides per value of ``lambda`` (batched), and equals the
balance's condensation through the springs (tests/hb/test_stability.py). From
:data:`MODAL_FROM` interior coordinates, where the modes of the structure with its contact
points held diagonalise every interior block (proportional or modal damping), the same
Schur complement is summed over those modes instead (:meth:`StructureDynamics.condensed`).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.linalg as sla

from fretwear.errors import InputError
from fretwear.hb.connectors import springs
from fretwear.hb.modal import ModalCondenser
from fretwear.hb.reduce import condenser_for
from fretwear.model.core import Model
from fretwear.resources import require_memory

#: at most this many interior DOFs: the exact transformation is formed densely; above, the
#: model needs a modal condenser (:func:`fretwear.hb.modal.modal_condenser`)
DENSE_INTERIOR_MAX = 600
MATRICES = ("K", "M", "C", "D")
#: from this many interior coordinates on, ``Z_r(lambda)`` is condensed through the held
#: structure's modes where they diagonalise every interior block (:meth:`StructureDynamics.
#: condensed`; below, Hill's method condenses in one compiled call and the solves are cheap)
MODAL_FROM = 17
#: an interior block is diagonal in the held modes when its projection's off-diagonal entries
#: are below this times its largest diagonal entry: the rounding of the projection, the
#: backward error of a solve with ``Z^qq`` itself
MODAL_DIAGONAL_TOL = 1e-12


@dataclass
class StructureDynamics:
    """The structure in coordinates ``(x, q)`` (module docstring): ``x`` (m,) the contact
    points the law acts on (the contact DOFs themselves, or the massless points behind the
    contact springs), ``q`` the rest (the structure's contact DOFs behind springs, then the
    interior coordinates).

    blocks : name (``"K"``, ``"M"``, ``"C"``, ``"D"``) -> ``(xx, xq, qx, qq)`` dense blocks in
        the contact-local frames ([N/m], [kg], [N s/m], [N/m]); ``C``, ``D`` absent when the
        model has none.
    load_x, load_q : (m,), (q,) the static loads (harmonic 0) on ``x`` and ``q`` [N].
    exact : the transformation is exact (no truncated modes).
    observe : (no, m + q) the displacements of the observed DOFs (global frame, in the order
        of ``model.observed`` and of their DOFs, as ``Reduced.obs_dofs``) from ``(x, q)``:
        ``u_o = observe @ [x; q]`` [m] (None: not formed).
    load1_x, load1_q : (m,), (q,) complex amplitudes of the loads' first harmonic on ``x`` and
        ``q`` [N] (``F(t) = Re(F_1 e^{i w t})``, as ``Model.load_harmonics``; the generalised
        forces of the same transformation as the static loads; None: not formed).
    """

    blocks: dict
    load_x: np.ndarray
    load_q: np.ndarray
    exact: bool
    observe: np.ndarray | None = None
    load1_x: np.ndarray | None = None
    load1_q: np.ndarray | None = None

    @property
    def m(self) -> int:
        return int(self.blocks["K"][0].shape[0])

    @property
    def q(self) -> int:
        return int(self.blocks["K"][3].shape[0])

    @cached_property
    def full(self) -> dict:
        """name -> the whole matrix ``[[xx, xq], [qx, qq]]`` (m + q, m + q) real, C-ordered
        (made once: the blocks do not change)."""
        out = {}
        for name, (xx, xq, qx, qq) in self.blocks.items():
            out[name] = (np.ascontiguousarray(np.block([[xx, xq], [qx, qq]]), dtype=float)
                         if self.q else np.ascontiguousarray(xx, dtype=float))
        return out

    @cached_property
    def held_modes(self) -> tuple[np.ndarray, np.ndarray] | None:
        """``(w2, Phi)``: the undamped modes of the structure with its contact points held,
        ``K^qq Phi = M^qq Phi diag(w2)`` with ``Phi^T M^qq Phi = I``, ascending (made once);
        None where ``q`` is empty or ``M^qq`` is not positive definite (a massless interior
        coordinate: no modal basis spans it). The basis in which Hill's method truncates the
        interior for its candidates (:meth:`fretwear.hb.stability.HillProblem.pencil`)."""
        if not self.q:
            return None
        Kqq = self.blocks["K"][3]
        Mqq = self.blocks["M"][3]
        try:
            w2, Phi = sla.eigh((Kqq + Kqq.T) / 2.0, (Mqq + Mqq.T) / 2.0)
        except (np.linalg.LinAlgError, ValueError):
            return None
        return w2, np.ascontiguousarray(Phi)

    @cached_property
    def _modal_interior(self) -> tuple | None:
        """Per matrix name, ``(xx, xq Phi, Phi^T qx, diag(Phi^T qq Phi))`` in the held modes
        ``Phi`` (:attr:`held_modes`), where every interior block is diagonal there (off the
        diagonal at most :data:`MODAL_DIAGONAL_TOL` of its largest entry: modal or Rayleigh
        damping, a hysteretic damping proportional to the stiffness); None otherwise (made
        once)."""
        modes = self.held_modes
        if modes is None:
            return None
        Phi = modes[1]
        out = {}
        for name, (xx, xq, qx, qq) in self.blocks.items():
            P = Phi.T @ qq @ Phi
            d = np.diag(P).copy()
            if np.max(np.abs(P - np.diag(d)), initial=0.0) > (
                    MODAL_DIAGONAL_TOL * np.max(np.abs(d), initial=0.0)):
                return None
            out[name] = (xx, xq @ Phi, Phi.T @ qx, d)
        return out

    @property
    def held_diagonal(self) -> bool:
        """The held structure's modes diagonalise every interior block (:attr:`_modal_interior`
        exists): a mode of a truncated interior that the contact does not see is then exact."""
        return self._modal_interior is not None

    def _condensed_modal(self, mass, visc, hyst) -> np.ndarray:
        """:meth:`condensed` through the held modes (:attr:`_modal_interior`): with ``q =
        Phi eta`` (every mode: the same Schur complement), ``Z^qq`` is diagonal, so ``Z_r =
        Z^xx - (Z^xq Phi) diag(z)^-1 (Phi^T Z^qx)`` costs ``m^2 q`` per value instead of a
        ``q x q`` solve (the virtual beam's 28 interior DOFs: 24 values 0.36 ms -> tens of
        us; the same ``Z_r`` to 1e-14 relative)."""
        mass, visc, hyst = (np.atleast_1d(np.asarray(x, dtype=complex))
                            for x in (mass, visc, hyst))
        coef = {"K": np.ones_like(mass), "M": mass, "C": visc, "D": hyst}
        xx = xq = qx = z = 0.0
        for name, (bxx, bxq, bqx, d) in self._modal_interior.items():
            c = coef[name][:, None, None]
            xx = xx + c * bxx
            xq = xq + c * bxq
            qx = qx + c * bqx
            z = z + coef[name][:, None] * d
        if np.any(z == 0):
            raise InputError("the structure with its contact points held is singular at a "
                             "value of the Laplace variable (an eigenvalue of the held "
                             "interface)")
        return xx - np.matmul(xq / z[:, None, :], qx)

    def assemble(self, mass, visc, hyst):
        """The blocks ``(xx, xq, qx, qq)`` of ``Z = K + a M + b C + c D`` for the coefficient
        arrays ``a``, ``b``, ``c`` (nl,): complex arrays (nl, ...), each C-ordered."""
        Z = self._whole(mass, visc, hyst)
        m = self.m
        return [np.ascontiguousarray(b) for b in (Z[:, :m, :m], Z[:, :m, m:], Z[:, m:, :m],
                                                 Z[:, m:, m:])]

    def _whole(self, mass, visc, hyst):
        """``Z = K + a M + b C + c D`` (nl, m + q, m + q) complex: entry by entry the same
        operations as on each block."""
        mass, visc, hyst = (np.atleast_1d(np.asarray(x, dtype=complex))
                            for x in (mass, visc, hyst))
        F = self.full
        Z = mass[:, None, None] * F["M"] + F["K"]
        if "C" in F:
            Z = Z + visc[:, None, None] * F["C"]
        if "D" in F:
            Z = Z + hyst[:, None, None] * F["D"]
        return Z

    def condensed(self, mass, visc, hyst) -> np.ndarray:
        """``Z_r`` (nl, m, m) complex seen by the contact law [N/m]: the Schur complement
        ``Z^xx - Z^xq (Z^qq)^-1 Z^qx`` (eq. 19, and :func:`fretwear.hb.connectors.connect`
        when there are contact springs)."""
        if not self.q:
            return self._whole(mass, visc, hyst)
        if self.q >= MODAL_FROM and self._modal_interior is not None:
            return self._condensed_modal(mass, visc, hyst)
        xx, xq, qx, qq = self.assemble(mass, visc, hyst)
        try:
            return xx - xq @ np.linalg.solve(qq, qx)
        except np.linalg.LinAlgError:
            raise InputError("the structure with its contact points held is singular at a "
                             "value of the Laplace variable (an eigenvalue of the held "
                             "interface)") from None


def _observation(cond, Psi_loc: np.ndarray, V: np.ndarray | None) -> np.ndarray:
    """``(no, m + q)``: the observed DOFs from the contact DOFs in their local frames ``u`` and
    the interior coordinates ``q`` (``U_c = R^T u``, ``U_i = Psi_loc u + V q``; ``V`` None:
    the identity), mapped back from the relative coordinates of node-to-node pairs
    (``U[obs_out] = S U'[obs]``, :class:`fretwear.hb.reduce.Structure`)."""
    m = cond.m
    R = np.asarray(cond.R.toarray() if hasattr(cond.R, "toarray") else cond.R, dtype=float)
    nq = cond.ni if V is None else V.shape[1]
    O = np.zeros((cond.structure.obs.size, m + nq))
    for j, c in cond.obs_c:
        O[j, :m] = R[:, c]
    for j, i in cond.obs_i:
        O[j, :m] = Psi_loc[i]
        if V is None:
            O[j, m + i] = 1.0
        else:
            O[j, m:] = V[i]
    S = cond.structure.S
    return O if S is None else np.asarray(S.toarray() @ O)


def _observation_with_springs(O: np.ndarray, m: int, contact) -> np.ndarray:
    """The rows of :func:`_observation` (``m`` contact DOFs) on ``(x, [u_f, q])``
    (:func:`_with_springs`)."""
    sp = springs(contact)
    if sp is None:
        return O
    Oc, Oq = O[:, :m], O[:, m:]
    Ox = np.zeros_like(Oc)
    Ox[:, sp.r] = Oc[:, sp.r]
    return np.hstack([Ox, Oc[:, sp.f], Oq])


def _with_springs(blocks: dict, load_c, load_q, contact):
    """The blocks on ``(x, [u_f, q])`` from those on ``(u, q)``: a contact spring ``k`` joins
    the structure's contact DOF ``u_f`` to a massless contact point ``x_f``; rigid directions
    keep ``x_r = u_r`` (:mod:`fretwear.hb.connectors`)."""
    sp = springs(contact)
    if sp is None:
        return blocks, load_c, load_q
    r, f, kf = sp.r, sp.f, sp.kf
    m, nf = load_c.size, f.size
    out = {}
    for name, (cc, cq, qc, qq) in blocks.items():
        q = qq.shape[0]
        xx = np.zeros((m, m), dtype=cc.dtype)
        xx[np.ix_(r, r)] = cc[np.ix_(r, r)]
        xq = np.zeros((m, nf + q), dtype=cc.dtype)
        xq[r, :nf] = cc[np.ix_(r, f)]
        xq[r, nf:] = cq[r]
        qx = np.zeros((nf + q, m), dtype=cc.dtype)
        qx[:nf, r] = cc[np.ix_(f, r)]
        qx[nf:, r] = qc[:, r]
        qq2 = np.zeros((nf + q, nf + q), dtype=cc.dtype)
        qq2[:nf, :nf] = cc[np.ix_(f, f)]
        qq2[:nf, nf:] = cq[f]
        qq2[nf:, :nf] = qc[:, f]
        qq2[nf:, nf:] = qq
        if name == "K":
            xx[f, f] += kf
            xq[f, np.arange(nf)] -= kf
            qx[np.arange(nf), f] -= kf
            qq2[np.arange(nf), np.arange(nf)] += kf
        out[name] = (xx, xq, qx, qq2)
    return (out, *_loads_with_springs(load_c, load_q, contact))


def _loads_with_springs(load_c, load_q, contact):
    """Loads ``(on x, on [u_f, q])`` from those on ``(u, q)`` (:func:`_with_springs`): a
    massless contact point carries no load."""
    sp = springs(contact)
    if sp is None:
        return load_c, load_q
    lx = np.zeros(load_c.size, dtype=np.result_type(load_c, load_q))
    lx[sp.r] = load_c[sp.r]
    return lx, np.concatenate([load_c[sp.f], load_q])


def check_dense(cond) -> None:
    """Refuse (one InputError with the estimate and the machine's memory) the dense
    matrices of :func:`structure_dynamics` that cannot fit, before they are formed: with a
    modal condenser the blocks on ``m + q`` coordinates and ``Psi R^T`` (``n_i x m``); else
    the blocks of ``K, M, C, D`` on every DOF (``(m + n_i)^2`` each, the partitions, the
    transformed blocks and their products); with the frame matrix ``R`` (``m x m``)."""
    m, ni = cond.m, cond.ni
    if isinstance(cond, ModalCondenser):
        nbytes = 8.0 * (2 * ni * m + 6 * (m + cond.q) ** 2 + m * m)
    elif ni > DENSE_INTERIOR_MAX:
        return  # refused below, with what to do instead
    else:
        nbytes = 8.0 * (12 * (m + ni) ** 2 + m * m)
    require_memory(nbytes, f"the dense structure matrices of Hill's method and nonlinear modes "
                   f"({m:,} contact and {ni:,} interior DOFs)")


def structure_dynamics(model: Model, condenser=None) -> StructureDynamics:
    """The :class:`StructureDynamics` of ``model``: that of its modal condenser when
    ``condenser`` is one (:func:`fretwear.hb.modal.modal_condenser`), else the exact
    transformation (at most :data:`DENSE_INTERIOR_MAX` interior DOFs; an InputError above,
    saying to pass a modal condenser)."""
    cond = condenser_for(model, condenser)
    if not getattr(cond, "models_in_time", True):  # a sector (hb/cyclic.py): Z(lambda) would
        raise InputError(  # be harmonic index 0's at every harmonic
            "condenser: Hill's method and nonlinear modes are not available on one sector "
            "with cyclic symmetry (fretwear.hb.cyclic) yet; use the whole disk "
            "(fretwear.model.cyclic.whole_disk)")
    check_dense(cond)
    if isinstance(cond, ModalCondenser):
        blocks = {name: tuple(np.asarray(b) for b in cond.proj_local[name])
                  for name in MATRICES if name in cond.proj_local}
        F0 = np.asarray(cond.structure.load_harmonics(0)[0].real, dtype=float)
        Fi = F0[cond.idofs]
        load_c = cond.R @ (F0[cond.cdofs] + cond.Psi.T @ Fi)
        load_q = cond.V.T @ Fi
        obs = _observation_with_springs(
            _observation(cond, cond.Psi @ np.asarray(
                cond.R.toarray() if hasattr(cond.R, "toarray") else cond.R).T, cond.V),
            cond.m, model.contact)
        F1 = cond.structure.load_harmonics(1)[1]
        l1 = _loads_with_springs(cond.R @ (F1[cond.cdofs] + cond.Psi.T @ F1[cond.idofs]),
                                 cond.V.T @ F1[cond.idofs], model.contact)
        return StructureDynamics(*_with_springs(blocks, load_c, load_q, model.contact), False,
                                 obs, *l1)
    if cond.ni > DENSE_INTERIOR_MAX:
        raise InputError(
            f"the model has {cond.ni} interior DOFs: Hill's method and nonlinear modes form "
            f"the structure's matrices densely up to {DENSE_INTERIOR_MAX}; pass a modal "
            "condenser (condenser=fretwear.modal_condenser(model, f_max, max_order))")
    R = np.asarray(cond.R.toarray() if hasattr(cond.R, "toarray") else cond.R, dtype=float)

    def dense(A):
        return A.toarray() if hasattr(A, "toarray") else np.asarray(A)

    parts = {}
    for name in MATRICES:
        B = getattr(cond, name)
        if B is not None:
            parts[name] = tuple(dense(getattr(B, p)) for p in ("cc", "ci", "ic", "ii"))
    Kcc, Kci, Kic, Kii = parts["K"]
    if cond.ni:
        try:
            Psi = -sla.solve(Kii, Kic)
        except (np.linalg.LinAlgError, sla.LinAlgError):
            raise InputError("the structure with its contact DOFs held is singular: part of "
                             "the model can move with nothing to hold it") from None
    else:
        Psi = np.zeros((0, cond.m))
    blocks = {}
    for name, (cc, ci, ic, ii) in parts.items():
        # u_c = R^T u_loc, u_i = Psi u_c + q: the blocks of T^T X T, T = [[I, 0], [Psi, I]]
        xcc = cc + ci @ Psi + Psi.T @ ic + Psi.T @ ii @ Psi
        xcq = ci + Psi.T @ ii
        xqc = ic + ii @ Psi
        blocks[name] = (R @ xcc @ R.T, R @ xcq, xqc @ R.T, ii)
    F0 = np.asarray(cond.structure.load_harmonics(0)[0].real, dtype=float)
    Fi = F0[cond.idofs]
    load_c = R @ (F0[cond.cdofs] + Psi.T @ Fi)
    obs = _observation_with_springs(_observation(cond, Psi @ R.T, None), cond.m,
                                   model.contact)
    F1 = cond.structure.load_harmonics(1)[1]
    l1 = _loads_with_springs(R @ (F1[cond.cdofs] + Psi.T @ F1[cond.idofs]),
                             F1[cond.idofs].copy(), model.contact)
    return StructureDynamics(*_with_springs(blocks, load_c, Fi.copy(), model.contact), True,
                             obs, *l1)
