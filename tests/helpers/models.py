"""Small hand-written models shared by several test files (independent of the FE layer)."""

import numpy as np
import scipy.sparse as sp

from fretwear.model.build import Damping
from fretwear.model.core import ContactInterface, Load, Model, ObservedPoint
from fretwear.model.matrices import ContactDofs, from_matrices

# --- a braced 2D truss with tilted contact frames (the condensation tests) ------------------
#: random numbers of tests/hb/test_reduce.py (truss() draws from its own generator)
RNG = np.random.default_rng(7)


def truss(nx=6, ny=3, a=0.01, k=1e7, m=0.01, damping="hysteretic", theta=0.3,
          dangling=False):
    """Braced 2D truss on an nx x ny grid (spacing a [m]), bar stiffness k*a/L [N/m], lumped
    mass m [kg] per node; bottom row = contact nodes with frames tilted by theta [rad]; statically
    supported by three fixed DOFs on the top row. ``dangling`` adds a node hanging on a single
    bar from a contact node (a mechanism that the contact does not hold). Its random loads are
    drawn from a generator seeded here: every call gives the same model, whatever ran before
    in the process (test order, pytest-xdist workers)."""
    rng = np.random.default_rng(7)
    xs, ys = np.meshgrid(np.arange(nx) * a, np.arange(ny) * a)
    pts = np.column_stack([xs.ravel(), ys.ravel()])
    nid = lambda i, j: j * nx + i
    bars = []
    for j in range(ny):
        for i in range(nx):
            if i + 1 < nx:
                bars.append((nid(i, j), nid(i + 1, j)))
            if j + 1 < ny:
                bars.append((nid(i, j), nid(i, j + 1)))
            if i + 1 < nx and j + 1 < ny:
                bars += [(nid(i, j), nid(i + 1, j + 1)), (nid(i + 1, j), nid(i, j + 1))]
    if dangling:
        pts = np.vstack([pts, [[-a, 0.0]]])
        bars.append((nid(0, 0), len(pts) - 1))
    nd = 2 * len(pts)
    K = np.zeros((nd, nd))
    for p, q in bars:
        e = pts[q] - pts[p]
        L = np.linalg.norm(e)
        c = e / L
        kb = k * a / L * np.outer(c, c)
        idx = np.r_[2 * p : 2 * p + 2, 2 * q : 2 * q + 2]
        K[np.ix_(idx, idx)] += np.block([[kb, -kb], [-kb, kb]])
    M = m * (1.0 + 0.1 * np.arange(nd) / nd)  # slightly non-uniform: no degenerate modes
    bottom = np.arange(nx)
    n = np.array([np.sin(theta), -np.cos(theta)])
    t = np.array([np.cos(theta), np.sin(theta)])
    contact = ContactInterface(
        dofs=np.column_stack([2 * bottom, 2 * bottom + 1]),
        frame=np.tile(np.array([n, t]), (nx, 1, 1)),
        gap=np.zeros(nx), area=np.full(nx, a), mu=0.3, coords=pts[bottom])
    top_left, top_right = nid(0, ny - 1), nid(nx - 1, ny - 1)
    fixed = np.array([2 * top_left, 2 * top_left + 1, 2 * top_right + 1])
    loads = [Load(rng.standard_normal(nd), "constant", name="static"),
             Load(rng.standard_normal(nd), "cos", name="c"),
             Load(rng.standard_normal(nd), "sin", name="s"),
             Load(rng.standard_normal(nd), "fourier", {2: (0.5, -0.2), 3: (0.0, 1.0)}, "f")]
    for ld in loads:
        ld.vector[fixed] = 0.0
    Ks = sp.csr_matrix(K)
    kw = {}
    if damping == "hysteretic":
        kw["D"] = 2e-3 * Ks
    elif damping == "rayleigh":
        kw["C"] = sp.csr_matrix(30.0 * np.diag(M) + 2e-7 * K)
    elif damping == "both":
        kw["D"] = 1e-3 * Ks
        kw["C"] = sp.csr_matrix(1e-7 * K)
    mid = nid(nx // 2, ny - 1)
    observed = [ObservedPoint("top", np.array([2 * mid, 2 * mid + 1]), pts[mid]),
                ObservedPoint("contact1", np.array([2, 3]), pts[1]),
                ObservedPoint("fixed", fixed[:2], pts[top_left])]
    return Model(K=Ks, M=sp.diags(M).tocsr(), contact=contact, loads=loads,
                 observed=observed, fixed_dofs=fixed, **kw)



# --- a one-node friction oscillator (Den Hartog's regime) ---------------------------------
M_, K_, KN, N0, F0, ZETA = 1.0, 1e4, 1e6, 10.0, 20.0, 0.05
MU = 0.3  # mu N0 / F0 = 0.15: continuous slip


def oscillator() -> Model:
    """DOF 0 normal (stiff spring, static load pressing it on the obstacle), DOF 1 tangential
    (mass, spring, viscous damping, harmonic force)."""
    K = sp.csr_matrix(np.diag([KN, K_]))
    M = sp.csr_matrix(np.diag([M_, M_]))
    C = sp.csr_matrix(np.diag([0.0, 2 * ZETA * np.sqrt(K_ * M_)]))
    contact = ContactInterface(dofs=np.array([[0, 1]]), frame=np.eye(2)[None],
                               gap=np.zeros(1), area=np.ones(1), mu=MU,
                               coords=np.zeros((1, 2)))
    loads = [Load(np.array([N0, 0.0]), "constant"), Load(np.array([0.0, F0]), "cos")]
    return Model(K=K, M=M, C=C, contact=contact, loads=loads,
                 observed=[ObservedPoint("x", np.array([1]), np.zeros(1))])



# --- independent sliders under a constant normal load (the wear tests) --------------------
KW = 1e-11  # Archard coefficient [1/Pa] (paper section 4)
MU_SLIDERS = 0.3


def sliders(nc=3, P=1e6, A=1e-4, kn=1.0, kt=1e8, ratio=3.0):
    """``nc`` independent contact nodes: normal DOF on a (soft) spring kn under the constant
    load P A, tangential DOF on a spring kt under ``ratio`` x mu P A sin(tau). Every node slides
    except near the load reversals; the normal force is exactly P A."""
    n = 2 * nc
    K = sp.diags(np.tile([kn, kt], nc)).tocsr()
    fn = np.zeros(n)
    fn[0::2] = P * A
    ft = np.zeros(n)
    ft[1::2] = ratio * MU_SLIDERS * P * A
    c = ContactInterface(dofs=np.arange(n).reshape(nc, 2), frame=np.tile(np.eye(2), (nc, 1, 1)),
                         gap=np.zeros(nc), area=np.full(nc, A), mu=MU_SLIDERS,
                         coords=np.c_[np.arange(nc) * 1e-3, np.zeros(nc)], wear_coefficient=KW)
    return Model(K=K, M=sp.csr_matrix((n, n)), contact=c,
                 loads=[Load(fn, "constant"), Load(ft, "sin")], dim=2)



# --- a contact node on a chain of masses (the time-domain tests) --------------------------
def chain(*, n=12, k=100.0, kg=30.0, mu=0.3, gap=0.0, N=5.0, F=2.0, ks_normal=0.0, c_a=0.0,
          c_b=0.0):
    """A contact node (DOFs 0 = normal, 1 = tangential) on a chain of ``n`` unit masses
    (DOFs 2..n+1) with springs k, the last mass grounded by ``kg`` (an undamped spring to
    ground), a force ``F cos(wt)`` on the last mass, and a constant normal load N. Damping
    ``c_a K0 + c_b M`` with ``K0`` the chain without the ground spring."""
    nd = n + 2
    rows, cols, vals = [], [], []

    def spring(i, j, kk):
        rows.extend([i, j, i, j])
        cols.extend([i, j, j, i])
        vals.extend([kk, kk, -kk, -kk])

    spring(1, 2, k)
    for i in range(2, n + 1):
        spring(i, i + 1, k)
    K0 = sp.csr_matrix((vals, (rows, cols)), shape=(nd, nd))
    Kn = sp.csr_matrix(([ks_normal], ([0], [0])), shape=(nd, nd))
    Kg = sp.csr_matrix(([kg], ([nd - 1], [nd - 1])), shape=(nd, nd))
    M = sp.identity(nd, format="csr")
    C = (c_a * K0 + c_b * M).tocsr() if (c_a or c_b) else None
    contact = ContactInterface(dofs=np.array([[0, 1]]), frame=np.eye(2)[None],
                               gap=np.array([gap]), area=np.ones(1), mu=mu,
                               coords=np.zeros((1, 2)))
    fN = np.zeros(nd)
    fN[0] = N
    fQ = np.zeros(nd)
    fQ[nd - 1] = F
    loads = [Load(fN, "constant", name="normal"), Load(fQ, "cos", name="Q")]
    return Model(K=(K0 + Kn + Kg).tocsr(), M=M, C=C, contact=contact, loads=loads,
                 observed=[ObservedPoint("end", np.array([nd - 1]), np.zeros(1)),
                           ObservedPoint("all", np.arange(nd), np.zeros(1))])


# --- two masses with a unilateral spring (the stability and dynamics tests) ---------------
K2 = np.array([[1.0, -1.0], [-1.0, 2.0]])  # two masses of 1 kg: springs 0, 1, 1 N/m
C2 = 0.03 * K2


def two_dof(kn=10.0, gap=0.5, force=0.1):
    """NLvib's example-03 family: two masses, damping 0.03 K, a unilateral spring ``kn`` with
    a ``gap`` on the first mass, a harmonic force on the second. The contact's tangential
    direction is a separate damped DOF (frictionless: it never couples)."""
    K = np.zeros((3, 3))
    K[:2, :2] = K2
    K[2, 2] = 1.0
    C = np.zeros((3, 3))
    C[:2, :2] = C2
    C[2, 2] = 1.0
    return from_matrices(K, np.eye(3),
                         contact=ContactDofs(normal_dofs=[0], tangential_dofs=[2], gap=gap,
                                             mu=0.0, kn=kn, kt=kn),
                         damping=Damping(C=C), loads=[Load(np.array([0.0, force, 0.0]), "cos")],
                         observed={"x1": 0, "x2": 1})
