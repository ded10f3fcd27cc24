"""Plain data objects describing a linear structure with a frictional contact interface.

Everything downstream (condensation, harmonic balance, wear, time integration, output)
takes a :class:`Model`. A model is built either from a finite element mesh
(:mod:`fretwear.model.build`) or from user matrices (:mod:`fretwear.model.matrices`); both
paths end here, so the solvers never know which one was used.

Conventions (SI units throughout):

* ``U`` is the vector of nodal displacements [m] in the structure's own axes; DOF ``2*i + c``
  (2D) or ``3*i + c`` (3D) for mesh node ``i`` and component ``c``; user matrices use their
  own numbering.
* A contact node has a local frame of ``d`` orthonormal rows: row 0 is the *normal* ``n``,
  pointing from the structure into the obstacle (the direction that closes the gap); rows
  ``1..d-1`` are the tangential directions. Local displacement ``u_loc = frame @ U[dofs]``.
* Signorini with wear (paper eq. 5): ``u_N - w - g <= 0``; ``g`` is the initial gap (>= 0 open).
* Contact forces ``lambda`` are the forces the structure exerts on the obstacle, in the local
  frame: ``lambda_N >= 0`` in compression (the paper uses the opposite sign), and the
  equation of motion is ``M U'' + C U' + K U + (frame^T lambda on contact DOFs) = F(t)``
  (paper eq. 11 and 19).
* Loads are ``F(t) = sum_k vector_k * g_k(omega t)`` with ``g_k`` a periodic waveform of
  period ``2 pi`` (:class:`Load`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

WAVEFORMS = ("constant", "cos", "sin", "triangle", "fourier")


@dataclass
class Load:
    """A load vector times a periodic waveform of ``tau = omega t``.

    Attributes
    ----------
    vector : (ndof,) float array, nodal forces [N].
    waveform : one of ``"constant"`` (static part), ``"cos"``, ``"sin"``, ``"triangle"``
        (amplitude 1, zero at ``tau = 0``, rising like ``sin``; Stromberg's linear load
        evolution), or ``"fourier"`` (user coefficients).
    coefficients : for ``"fourier"`` only: dict ``{n: (a_n, b_n)}`` so that
        ``g(tau) = sum_n a_n cos(n tau) + b_n sin(n tau)`` (``n = 0`` gives the mean, ``b_0``
        ignored).
    name : label used in output.
    """

    vector: np.ndarray
    waveform: str = "cos"
    coefficients: dict | None = None
    name: str = "load"

    def fourier_coefficients(self, nmax: int) -> tuple[np.ndarray, np.ndarray]:
        """Real Fourier coefficients ``a_n, b_n`` (n = 0..nmax) of the waveform.

        ``g(tau) = a_0 + sum_{n>=1} a_n cos(n tau) + b_n sin(n tau)``. Exact for the analytic
        waveforms; the triangle uses its closed-form series ``8/(pi^2 n^2) (-1)^((n-1)/2)``
        on odd sines.
        """
        a = np.zeros(nmax + 1)
        b = np.zeros(nmax + 1)
        w = self.waveform
        if w == "constant":
            a[0] = 1.0
        elif w == "cos":
            if nmax >= 1:
                a[1] = 1.0
        elif w == "sin":
            if nmax >= 1:
                b[1] = 1.0
        elif w == "triangle":
            for n in range(1, nmax + 1, 2):
                b[n] = 8.0 / (np.pi**2 * n**2) * (-1.0) ** ((n - 1) // 2)
        elif w == "fourier":
            for n, (an, bn) in (self.coefficients or {}).items():
                n = int(n)
                if 0 <= n <= nmax:
                    a[n] = an
                    b[n] = 0.0 if n == 0 else bn
        else:
            raise ValueError(
                f"load {self.name!r}: unknown waveform {w!r}; expected one of {WAVEFORMS}"
            )
        return a, b

    def waveform_samples(self, tau: np.ndarray) -> np.ndarray:
        """The waveform ``g(tau)`` evaluated at the angles ``tau`` [rad] (exact, no truncation)."""
        w = self.waveform
        tau = np.asarray(tau, dtype=float)
        if w == "constant":
            return np.ones_like(tau)
        if w == "cos":
            return np.cos(tau)
        if w == "sin":
            return np.sin(tau)
        if w == "triangle":
            return (2.0 / np.pi) * np.arcsin(np.sin(tau))
        if w == "fourier":
            out = np.zeros_like(tau)
            for n, (an, bn) in (self.coefficients or {}).items():
                n = int(n)
                out += an * np.cos(n * tau) + (0.0 if n == 0 else bn * np.sin(n * tau))
            return out
        raise ValueError(f"load {self.name!r}: unknown waveform {w!r}; expected one of {WAVEFORMS}")


@dataclass
class Segments:
    """Node-to-segment partners of the contact nodes (non-matching interface meshes).

    dofs : (nc, k, d) int, the DOFs of the ``k`` nodes of the facet each contact node faces
        (``-1`` pads shorter facets and node-to-rigid nodes).
    weights : (nc, k) float, the facet's shape functions ``N_k(xi)`` at the projection of
        the contact node (they add up to 1; 0 for padding): the partner displacement is
        ``sum_k N_k U[dofs[:, k]]``.
    ids : (nc, k) int, mesh node numbers of the facet nodes (``-1``: padding).
    """

    dofs: np.ndarray
    weights: np.ndarray
    ids: np.ndarray


@dataclass
class ContactInterface:
    """The contact nodes of a model: one per-node record for all its interfaces.

    A node is either *node-to-rigid* (it touches a rigid obstacle) or one node ``a`` of a
    *node-to-node pair* ``(a, b)`` between two elastic bodies (or two parts of one body). The
    contact law acts on the displacement of ``a`` relative to the obstacle, or relative to
    its partner ``b``: ``u_loc = frame @ (U[dofs] - U[partner_dofs])`` (paper subscript r,
    eq. 19-23); the pair's contact forces are equal and opposite on ``a`` and ``b``. Several
    named interfaces share this one record (``interface`` holds each node's interface index
    into ``interface_names``), so the harmonic balance and the wear integration run on plain
    per-node arrays whatever the number of interfaces.

    Attributes
    ----------
    dofs : (nc, d) int array, global DOFs of each contact node (node ``a`` of a pair).
    frame : (nc, d, d) float array, rows ``[n, t1(, t2)]`` (see module docstring); for a pair
        ``n`` points from node ``a`` into the body of node ``b``.
    gap : (nc,) initial normal gap [m] (>= 0 means open).
    area : (nc,) tributary area [m^2] (2D plane strain: tributary length x width).
    mu : Coulomb friction coefficient [-]: one number, or (nc,) per node.
    coords : (nc, d) node positions [m] (for output; zeros for user matrices if unknown).
    node_ids : (nc,) mesh node numbers, or -1 when built from matrices.
    wear_coefficient : Archard coefficient k_w [1/Pa] (eq. 29) of the surface of node ``a``
        (the structure's side against a rigid obstacle): one number or (nc,) per node.
    name : label (of the first interface when there are several).
    partner_dofs : (nc, d) int array, the DOFs of each node's partner ``b`` (same axes as
        ``dofs``), ``-1`` for a node-to-rigid node; None: every node is node-to-rigid.
    partner_ids : (nc,) mesh node numbers of the partners (-1 where none), for output.
    partner_wear_coefficient : Archard coefficient [1/Pa] of the partner's surface: one
        number or (nc,) per node (0 for node-to-rigid nodes: a rigid obstacle does not wear).
        The gap of a pair opens by the sum of both worn depths.
    interface : (nc,) int, each node's interface (index into ``interface_names``); None: one
        interface, named ``name``.
    interface_names : the interfaces' names, in the order of their indices.
    normal_load : friction under a prescribed normal load: a :class:`Load` whose ``vector``
        (nc,) holds each node's normal force [N] (NaN: that node is in unilateral contact) and
        whose waveform gives its time history ``N(t) = vector * g(omega t)`` (``"constant"``,
        ``"cos"``, ``"fourier"``...). On such a node the normal contact force is ``N(t)``
        whatever the normal displacement, and the slip threshold is ``mu N(t)``
        (:mod:`fretwear.hb.contact`). None: every node in unilateral contact (default).
    kn, kt : (nc,) normal and tangential contact stiffness [N/m] per node, a physical property
        of the interface in series with the contact law (:mod:`fretwear.hb.connectors`):
        ``inf`` is a rigid contact (default), a finite ``kt`` with a rigid normal is a
        Jenkins element. None: rigid everywhere.
    segments : node-to-segment pairs (non-matching meshes, :class:`Segments`): node ``a``
        faces a point of a facet of the other body, whose displacement is the facet nodes'
        interpolated by the weights ``N_k``; ``partner_dofs`` then holds the facet node of the
        largest weight (for output). None: every pair is node-to-node.
    """

    dofs: np.ndarray
    frame: np.ndarray
    gap: np.ndarray
    area: np.ndarray
    mu: float | np.ndarray
    coords: np.ndarray
    node_ids: np.ndarray | None = None
    wear_coefficient: float | np.ndarray = 0.0
    name: str = "contact"
    partner_dofs: np.ndarray | None = None
    partner_ids: np.ndarray | None = None
    partner_wear_coefficient: float | np.ndarray = 0.0
    interface: np.ndarray | None = None
    interface_names: tuple = ()
    normal_load: Load | None = None
    kn: np.ndarray | None = None
    kt: np.ndarray | None = None
    segments: Segments | None = None

    @property
    def n_nodes(self) -> int:
        return int(self.dofs.shape[0])

    @property
    def dim(self) -> int:
        return int(self.dofs.shape[1])

    def _per_node(self, value) -> np.ndarray:
        return np.broadcast_to(np.asarray(value, dtype=float), (self.n_nodes,)).copy()

    def mu_nodes(self) -> np.ndarray:
        """Friction coefficient of every node (nc,) [-]."""
        return self._per_node(self.mu)

    def wear_nodes(self) -> np.ndarray:
        """Archard coefficient of the surface of every node ``a`` (nc,) [1/Pa]."""
        return self._per_node(self.wear_coefficient)

    def partner_wear_nodes(self) -> np.ndarray:
        """Archard coefficient of every partner's surface (nc,) [1/Pa] (0 without partner)."""
        return np.where(self.paired(), self._per_node(self.partner_wear_coefficient), 0.0)

    def partner_terms(self) -> tuple[np.ndarray, np.ndarray]:
        """``(dofs, weights)``, (nc, k, d) int and (nc, k) float: the partner displacement
        of node ``p`` is ``sum_k weights[p, k] U[dofs[p, k]]`` (``-1`` DOFs and zero weights
        pad a node with fewer terms; a node-to-node pair is one term of weight 1; a
        node-to-rigid node none)."""
        if self.segments is not None:
            return (np.asarray(self.segments.dofs, dtype=np.int64),
                    np.asarray(self.segments.weights, dtype=float))
        nc, d = self.dofs.shape
        if self.partner_dofs is None:
            return np.full((nc, 1, d), -1, dtype=np.int64), np.zeros((nc, 1))
        pd = np.asarray(self.partner_dofs, dtype=np.int64)
        return pd[:, None, :], (pd[:, :1] >= 0).astype(float)

    def paired(self) -> np.ndarray:
        """(nc,) bool: which nodes are node ``a`` of a node-to-node pair."""
        if self.partner_dofs is None:
            return np.zeros(self.n_nodes, dtype=bool)
        return np.asarray(self.partner_dofs)[:, 0] >= 0

    @property
    def has_pairs(self) -> bool:
        return bool(np.any(self.paired()))

    def interface_index(self) -> np.ndarray:
        """(nc,) int: the interface of every node (all 0 for one interface)."""
        if self.interface is None:
            return np.zeros(self.n_nodes, dtype=np.int64)
        return np.asarray(self.interface, dtype=np.int64)

    def names(self) -> list[str]:
        """The interfaces' names, in the order of :meth:`interface_index`."""
        return list(self.interface_names) if self.interface_names else [self.name]
    @property
    def has_springs(self) -> bool:
        """A finite contact stiffness on some node (:mod:`fretwear.hb.connectors`)."""
        return any(k is not None and not np.all(np.isinf(k)) for k in (self.kn, self.kt))

    @property
    def has_connectors(self) -> bool:
        """Contact stiffness or a prescribed normal load on some node: the interface is more
        than the rigid unilateral contact with Coulomb friction."""
        return self.has_springs or self.prescribed_nodes().any()

    def prescribed_nodes(self) -> np.ndarray:
        """(nc,) bool: the nodes whose normal force is prescribed (``normal_load``)."""
        if self.normal_load is None:
            return np.zeros(self.n_nodes, dtype=bool)
        return ~np.isnan(np.asarray(self.normal_load.vector, float))

    def normal_force_samples(self, tau) -> np.ndarray:
        """Prescribed normal forces ``N(tau)`` (nc, len(tau)) [N] at the angles ``tau =
        omega t`` (exact samples of the waveform), NaN rows for unilateral nodes; None when no
        node has a prescribed normal load."""
        if not self.prescribed_nodes().any():
            return None
        vec = np.asarray(self.normal_load.vector, float)
        return np.outer(vec, self.normal_load.waveform_samples(np.asarray(tau, float)))

    def local_transform(self, ndof: int) -> sp.csr_matrix:
        """Sparse ``T`` (nc*d x ndof) with ``u_loc = T @ U`` (relative to the partner for a
        pair); rows node-major ``[N, T1, (T2)]``."""
        nc, d = self.dofs.shape
        rows = np.repeat(np.arange(nc * d), d)
        cols = np.broadcast_to(self.dofs[:, None, :], (nc, d, d)).reshape(-1)
        vals = self.frame.reshape(-1)
        T = sp.csr_matrix((vals, (rows, cols)), shape=(nc * d, ndof))
        if self.has_pairs:
            pdofs, weights = self.partner_terms()
            for k in range(weights.shape[1]):
                pd = np.where(weights[:, k, None] != 0.0, pdofs[:, k], -1)
                keep = np.broadcast_to(pd[:, None, :] >= 0, (nc, d, d)).reshape(-1)
                pcols = np.broadcast_to(pd[:, None, :], (nc, d, d)).reshape(-1)
                w = vals if self.segments is None else \
                    vals * np.repeat(weights[:, k], d * d)
                T = T - sp.csr_matrix((w[keep], (rows[keep], pcols[keep])),
                                      shape=(nc * d, ndof))
        return T.tocsr()


@dataclass
class ObservedPoint:
    """A point whose motion is reported: its DOFs (one per axis) and position [m]."""

    name: str
    dofs: np.ndarray
    coords: np.ndarray


@dataclass
class Mesh:
    """A finite element mesh kept with the model for output (ParaView fields, profiles).

    points : (nn, d) node coordinates [m]; cells : (ne, k) connectivity; cell_type : meshio
    name (``"quad"``, ``"triangle"``, ``"hexahedron"``, ``"tetra"``); boundaries : name ->
    (nf, kf) facet connectivity; node_sets : name -> node numbers.
    rows : (nn, d) the DOF of each point's translations (-1: none), or None when the DOFs are
    node-major (``d * i + c``, meshed models); set on the points of a model built from an FE
    code's matrices (:attr:`Model.fe_mesh`). ids : (nn,) the FE code's node id of each point,
    or None (the contact's ``node_ids`` are then point numbers).
    """

    points: np.ndarray
    cells: np.ndarray
    cell_type: str
    boundaries: dict[str, np.ndarray] = field(default_factory=dict)
    node_sets: dict[str, np.ndarray] = field(default_factory=dict)
    rows: np.ndarray | None = None
    ids: np.ndarray | None = None

    def point_index(self, ids) -> np.ndarray:
        """The point numbers of node ids (of ``ids`` when set; else the ids are numbers)."""
        ids = np.asarray(ids, dtype=np.int64)
        if self.ids is None:
            return ids
        order = np.argsort(self.ids)
        return order[np.searchsorted(self.ids[order], ids)]

    @property
    def dim(self) -> int:
        return int(self.points.shape[1])


@dataclass
class Model:
    """A linear structure with frictional contact interfaces (paper eq. 11).

    K, M : (ndof, ndof) sparse stiffness [N/m] and mass [kg] (M may be singular).
    C : viscous damping [N s/m] or None.
    D : hysteretic damping matrix [N/m] or None: on harmonic ``n >= 1`` the dynamic stiffness
        is ``K + i D - (n w)^2 M + i n w C`` (a loss factor eta gives ``D = eta K``); it
        has no static part.
    loads : list of :class:`Load`.
    contact : the contact nodes of every interface (one per-node record).
    observed : points whose motion is reported.
    fixed_dofs : DOFs held at zero (Dirichlet), removed before any solve.
    dim : 2 (plane strain) or 3.
    mesh : the mesh, when built from one.
    fe_mesh : for a model built from an FE code's matrices with its node file, the nodes (and
        elements) of that file as a :class:`Mesh` with ``rows`` and ``ids``, for ParaView
        output only (``mesh`` stays None: nothing else reads it); None otherwise.
    thickness : out-of-plane width [m] (2D only; 1 for matrices).
    """

    K: sp.csr_matrix
    M: sp.csr_matrix
    contact: ContactInterface
    C: sp.csr_matrix | None = None
    D: sp.csr_matrix | None = None
    loads: list[Load] = field(default_factory=list)
    observed: list[ObservedPoint] = field(default_factory=list)
    fixed_dofs: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    dim: int = 2
    mesh: Mesh | None = None
    fe_mesh: Mesh | None = None
    thickness: float = 1.0
    name: str = "model"
    meta: dict = field(default_factory=dict)

    @property
    def ndof(self) -> int:
        return int(self.K.shape[0])

    def free_dofs(self) -> np.ndarray:
        mask = np.ones(self.ndof, dtype=bool)
        mask[np.asarray(self.fixed_dofs, dtype=np.int64)] = False
        return np.flatnonzero(mask)

    def load_harmonics(self, nmax: int) -> np.ndarray:
        """Complex load amplitudes ``F_n`` (nmax+1, ndof) [N]: ``F(t) = Re sum F_n e^{i n w t}``.

        ``F_0`` is the static load (real); for ``n >= 1``, ``F_n = a_n - i b_n`` in terms of the
        real cosine/sine coefficients.
        """
        out = np.zeros((nmax + 1, self.ndof), dtype=complex)
        for load in self.loads:
            a, b = load.fourier_coefficients(nmax)
            out += np.outer(a - 1j * b, load.vector)
        return out

    def load_time(self, tau: np.ndarray) -> np.ndarray:
        """Load vectors at angles ``tau`` (len(tau), ndof) [N], exact (no truncation)."""
        tau = np.atleast_1d(np.asarray(tau, dtype=float))
        out = np.zeros((tau.size, self.ndof))
        for load in self.loads:
            out += np.outer(load.waveform_samples(tau), load.vector)
        return out

    def observed_point(self, name: str) -> ObservedPoint:
        for p in self.observed:
            if p.name == name:
                return p
        names = [p.name for p in self.observed]
        raise KeyError(f"no observed point named {name!r}; the model has {names}")
