"""The DLFT balance of one reduced model at one frequency: residual and Jacobian (paper
eq. 19-28).

Unknowns are the real Fourier coefficients ``U~`` of the contact-local displacements
(``m = n_contact * d`` DOFs, ``H = 1 + 2k`` coefficients each), stored *DOF-major* as an
``(m, H)`` array. The residual is (eq. 22)

    f(U~) = eps (U~ - W~ - X~),         X~ = lambda_x~ / eps,

with ``lambda_x`` from the time-domain law of :mod:`fretwear.hb.contact` applied to
``lambda_u = F~ - Z U~ + eps (U~ - W~)`` (eq. 23). ``W~`` holds gap + wear on the normal DOFs
(static term). The Jacobian is ``J = eps I - G (eps I - Z)`` with ``G = d lambda_x~/d lambda_u~``
block-diagonal per node.
"""

from __future__ import annotations

import numpy as np

from fretwear.errors import InputError
from fretwear.hb import contact as law
from fretwear.hb import small
from fretwear.hb.connectors import connect, springs
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.krylov import KrylovJacobian
from fretwear.hb.operator_blocks import harmonic_blocks
from fretwear.hb.options import JACOBIANS, KRYLOV
from fretwear.hb.penalty import penalty
from fretwear.hb.reduce import Reduced, loads_to_real, to_real_blocks
from fretwear.hb.solvers import vector_norm
from fretwear.model.core import ContactInterface

#: ``"auto"`` forms the Jacobian up to this many unknowns ``m H`` (docs/theory.md, "Large
#: interfaces": measured crossover, benchmarks/scale_3d.py)
DENSE_JACOBIAN_MAX = 3000


class DLFTProblem:
    """Residual and Jacobian of the DLFT balance for one reduced model (one frequency).

    Parameters
    ----------
    reduced : :class:`~fretwear.hb.reduce.Reduced` on the orders ``[0] + basis.harmonics``.
    contact : the contact record (friction coefficient per node: ``contact.mu_nodes()``).
    basis : Fourier basis.
    gap : (nc,) normal gap + wear ``W`` [m].
    eps : DLFT penalty: ``"auto"`` (default) the spectral radius of ``Z_r`` (paper, section
        3.2), ``"static"`` that of the static ``K_r``, or a positive number [N/m]
        (:func:`fretwear.hb.penalty.penalty`).
    anchor : (nc, d-1) stick anchors: where a node that sticks all period sticks [m]
        (tangential, contact-local). Default 0.
    jacobian : how the Newton step is computed (:data:`JACOBIANS`): ``"auto"`` (default)
        forms the Jacobian up to :data:`DENSE_JACOBIAN_MAX` unknowns and uses it as an
        operator (GMRES with per-harmonic factorisations) above.

    Contact springs of the interface (``contact.kn``, ``contact.kt``) are applied to
    ``reduced`` here (:func:`fretwear.hb.connectors.connect`): the unknowns are then the
    contact points in series with the springs. Nodes with a prescribed normal load
    (``contact.normal_load``) take ``lambda_N = N(t)`` and the slip threshold ``mu N(t)``.
    """

    #: the linear algebra of the Newton step on the operator path
    #: (:class:`fretwear.hb.options.KrylovOptions`; a driver sets ``options.krylov``, and the
    #: problems made from this one by :meth:`at` and :meth:`with_eps` keep it)
    krylov = KRYLOV

    def __init__(self, reduced: Reduced, contact: ContactInterface, basis: FourierBasis,
                 gap=None, eps="auto", anchor=None, periodicity_tol=1e-12, max_sweeps=200,
                 jacobian="auto"):
        nc, d = contact.dofs.shape
        self.nc, self.d, self.basis = nc, d, basis
        self.H = basis.size
        self.m = nc * d
        exp = np.array([0, *basis.harmonics])
        if not np.array_equal(np.asarray(reduced.orders), exp):
            raise InputError(f"reduced model orders {list(reduced.orders)} != basis {list(exp)}")
        self._springs = springs(contact)
        if self._springs is not None:
            reduced = connect(reduced, contact, self._springs)
        self.reduced = reduced
        self.contact = contact
        self.blocks = harmonic_blocks(reduced.Z)
        self._Z = None
        self._zu = None
        if jacobian not in JACOBIANS:
            raise InputError(f"jacobian = {jacobian!r}: expected one of {JACOBIANS}")
        if jacobian == "auto":
            jacobian = "dense" if self.m * self.H <= DENSE_JACOBIAN_MAX else "krylov"
        self.jacobian = jacobian
        self.F = loads_to_real(reduced.F)
        self._eps_rule = eps
        self.eps = penalty(eps, reduced=reduced, contact=contact)
        self._Fnorm = None
        self.mu = contact.mu_nodes()
        self.normal = contact.normal_force_samples(basis.tau)  # None: all unilateral
        self.set_gap(contact.gap if gap is None else gap)
        self.anchor = np.zeros((nc, d - 1)) if anchor is None else np.array(anchor, float)
        # the basis's shared read-only matrices, copied as the kernels take them
        # (law.kernel_array: one compilation of each kernel)
        self.P, self.Q = (law.kernel_array(a) for a in basis.matrices())
        # small problems: residual and Jacobian in one compiled call (hb/small.py)
        self.small = self.jacobian == "dense" and self.m * self.H <= small.SMALL_MAX
        # the normal force at every sample (the law's kernels take it; Hill's method too)
        self.normal_samples = law._normal(self.normal, np.empty((nc, d, basis.n_samples)))
        self.tol = periodicity_tol
        self.max_sweeps = max_sweeps
        self.nfev = 0

    def at(self, reduced: Reduced, anchor) -> DLFTProblem:
        """The same problem (interface, basis, gap, eps rule, settings) on the reduced model
        of another frequency (same orders), with the stick anchors ``anchor`` (nc, d-1) [m].
        What does not depend on the frequency (the Fourier matrices, friction coefficients,
        prescribed normal forces, a numeric eps, the contact springs) is shared, not rebuilt:
        a sweep makes one problem per frequency."""
        if isinstance(self._eps_rule, str):  # a rule evaluated on each reduced model
            out = DLFTProblem(reduced, self.contact, self.basis, gap=self.gap,
                              eps=self._eps_rule, anchor=anchor, periodicity_tol=self.tol,
                              max_sweeps=self.max_sweeps, jacobian=self.jacobian)
            out.krylov = self.krylov
            return out
        new = object.__new__(DLFTProblem)  # a shallow copy (copy.copy: slower)
        new.__dict__.update(self.__dict__)
        if self._springs is not None:
            reduced = connect(reduced, self.contact, self._springs)
        new.reduced = reduced
        new.blocks = harmonic_blocks(reduced.Z)
        new._Z = new._zu = None
        new.F = loads_to_real(reduced.F)
        new._Fnorm = None
        new.anchor = (np.zeros((self.nc, self.d - 1)) if anchor is None
                      else np.array(anchor, float))
        new.nfev = 0
        return new

    def with_eps(self, eps: float) -> DLFTProblem:
        """The same problem (reduced model, gap, anchors) with the penalty ``eps`` [N/m]."""
        out = DLFTProblem(self.reduced, self.contact, self.basis, gap=self.gap, eps=eps,
                          anchor=self.anchor, periodicity_tol=self.tol,
                          max_sweeps=self.max_sweeps, jacobian=self.jacobian)
        out.krylov = self.krylov
        return out

    def set_gap(self, gap):
        gap = np.broadcast_to(np.asarray(gap, dtype=float), (self.nc,))
        W = np.zeros((self.m, self.H))
        W[0 :: self.d, 0] = gap
        self.gap = np.array(gap)
        self.W = W

    @property
    def Z(self) -> np.ndarray:
        """The real block operator ``Z~`` (m*H, m*H), DOF-major
        (:func:`~fretwear.hb.reduce.to_real_blocks`), formed on first use."""
        if self._Z is None:
            Z = self.reduced.Z
            if not isinstance(Z, np.ndarray):  # a ReducedOperator (hb/modal_operator.py)
                Z = np.stack(list(Z))
            self._Z = to_real_blocks(Z, self.reduced.orders)
        return self._Z

    def apply_Z(self, U) -> np.ndarray:
        """``Z~ U~`` (m, H): with the formed ``Z~`` on the dense path, by harmonic blocks
        (:class:`~fretwear.hb.krylov.HarmonicBlocks`) on the operator path; always the same
        way for one problem, so that a result re-assembled from saved harmonics is bitwise
        the one of the solve."""
        if self.jacobian == "dense":
            return (self.Z @ np.reshape(U, -1)).reshape(self.m, self.H)
        return self.blocks.apply(U)

    # -- evaluation ---------------------------------------------------------------------
    def lambda_u(self, U):
        """``lambda_u~ = F~ - Z U~ + eps (U~ - W~)`` (m, H) (eq. 23)."""
        ZU = self.apply_Z(U)
        if self.jacobian == "krylov":  # |Z U~| of the convergence test at the same U~
            self._zu = (np.array(U, dtype=float), vector_norm(ZU))
        return self.F - ZU + self.eps * (U - self.W)

    def time_law(self, U):
        """Time-domain law: ``(lam_u, lam_x, state, sweeps)`` with samples (nc, d, N)."""
        if self.small:
            return small.time_law(self._flat(U), self.Z, self.F.reshape(-1),
                                  self.W.reshape(-1), self.eps, self.Q, self.mu,
                                  self._x_start(), self.tol, self.max_sweeps, self.normal_samples,
                                  self.nc, self.d)
        lu = self.basis.to_time(self.lambda_u(U)).reshape(self.nc, self.d, -1)
        lu = np.ascontiguousarray(lu)
        lx, state, sweeps = law.dlft_time(lu, self.mu, self.eps * self.anchor, self.tol,
                                          self.max_sweeps, self.normal)
        return lu, lx, state, sweeps

    def to_freq(self, samples) -> np.ndarray:
        """Real coefficients (k, H) of time samples (k, N), as the residual takes them: by
        the forward matrix ``P`` on the small-problem path, by FFT otherwise."""
        if self.small:
            return samples @ self.P.T
        return self.basis.to_freq(samples)

    def _flat(self, U):
        return np.ascontiguousarray(U, dtype=float).reshape(-1)

    def _x_start(self):
        return np.ascontiguousarray(self.eps * self.anchor, dtype=float).reshape(self.nc,
                                                                                  self.d - 1)

    def residual(self, U, jacobian=True):
        """``f`` (m*H,) and, if asked, ``J`` (m*H, m*H) at ``U`` (m, H)."""
        self.nfev += 1
        if self.small:
            f, J = small.residual(self._flat(U), self.Z, self.F.reshape(-1),
                                  self.W.reshape(-1), self.eps, self.P, self.Q, self.mu,
                                  self._x_start(), self.tol, self.max_sweeps, self.normal_samples,
                                  self.nc, self.d, bool(jacobian))
            return f, (J if jacobian else None)
        lu, lx, state, _ = self.time_law(U)
        Lx = self.basis.to_freq(lx.reshape(self.m, -1))
        f = (self.eps * (U - self.W) - Lx).reshape(-1)
        if not jacobian:
            return f, None
        G = law.dlft_jacobian(lu, lx, state, self.mu, self.P, self.Q, self.eps * self.anchor,
                              self.tol, self.max_sweeps, self.normal)
        if self.jacobian == "krylov":
            return f, KrylovJacobian(G, self.blocks, self.eps, self.d, owner=self)
        n = self.m * self.H
        dH = self.d * self.H
        # J = eps I - G (eps I - Z) = eps (I - G) + G Z, G block-diagonal per node
        GZ = np.matmul(G, self.Z.reshape(self.nc, dH, n)).reshape(n, n)
        J = GZ
        for p in range(self.nc):
            sl = slice(p * dH, (p + 1) * dH)
            J[sl, sl] -= self.eps * G[p]
        J[np.diag_indices(n)] += self.eps
        return f, J

    def scale(self, U):
        """Reference magnitude of the convergence test: ``|Z_r U~|`` (section 3.2), or |F~|
        when that vanishes."""
        kept = self._zu
        if kept is not None and np.array_equal(kept[0], U):  # from the residual at this U
            zu = kept[1]
        else:
            zu = vector_norm(self.apply_Z(U))
        if self._Fnorm is None:
            self._Fnorm = float(np.linalg.norm(self.F))
        return max(zu, self._Fnorm, 1e-300)

    def initial_guess(self):
        """Contact closed, tangential positions at the anchors, no vibration."""
        U = np.zeros((self.m, self.H))
        U[0 :: self.d, 0] = self.gap
        for c in range(self.d - 1):
            U[1 + c :: self.d, 0] = self.anchor[:, c]
        return U
