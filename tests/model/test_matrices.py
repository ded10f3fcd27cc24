"""Models from user matrices (fretwear.model.matrices).

The reference is a spring-mass chain whose Model is written out by hand from the core
data-object conventions, and Matrix Market files written by scipy itself. All comparisons
are exact: the function only copies, symmetrises (already symmetric input) and validates.
"""

import numpy as np
import pytest
import scipy.io
import scipy.sparse as sp

from fretwear.errors import InputError
from fretwear.model.build import Damping
from fretwear.model.core import ContactInterface, Load, Model, ObservedPoint
from fretwear.model.matrices import ContactDofs, from_matrices, read_matrix_market

k1, k2, k3 = 2e6, 1e6, 5e5
m1, m2 = 0.3, 0.1


def chain():
    """Ground -k1- mass 1 -k2- mass 2 (contact node, normal DOF 1) with a tangential DOF 2
    held to ground by k3 and massless."""
    K = np.array([[k1 + k2, -k2, 0.0], [-k2, k2, 0.0], [0.0, 0.0, k3]])
    M = np.diag([m1, m2, 0.0])
    return K, M


def test_chain_matches_hand_built_model():
    """from_matrices against the Model written by hand: contact node with DOFs [1, 2],
    frame diag(-1, 1) for normal_sign = -1, gap, area, mu, D = eta K, the load and the
    observed DOF."""
    K, M = chain()
    f = np.array([1.0, 0.0, 0.0])
    got = from_matrices(K, sp.csr_matrix(M),
                        contact=ContactDofs(normal_dofs=[1], tangential_dofs=[2], gap=1e-6,
                                            area=2e-4, mu=0.4, normal_sign=-1,
                                            wear_coefficient=1e-11, coords=[[0.5, 0.0]]),
                        damping=Damping(loss_factor=0.01), loads=[Load(f, "cos", name="drive")],
                        observed={"mass 1": 0}, name="chain")
    hand = Model(
        K=sp.csr_matrix(K), M=sp.csr_matrix(M),
        contact=ContactInterface(dofs=np.array([[1, 2]]), frame=np.array([[[-1.0, 0.0],
                                                                           [0.0, 1.0]]]),
                                 gap=np.array([1e-6]), area=np.array([2e-4]), mu=0.4,
                                 coords=np.array([[0.5, 0.0]]), node_ids=np.array([-1]),
                                 wear_coefficient=1e-11),
        D=sp.csr_matrix(0.01 * K), loads=[Load(f, "cos", name="drive")],
        observed=[ObservedPoint("mass 1", np.array([0]), np.zeros(1))], dim=2, name="chain")
    for a in ("K", "M", "D"):
        assert abs(getattr(got, a) - getattr(hand, a)).max() == 0.0, a
    assert got.C is None and got.mesh is None and got.thickness == 1.0 and got.dim == 2
    for a in ("dofs", "frame", "gap", "area", "coords", "node_ids"):
        np.testing.assert_array_equal(getattr(got.contact, a), getattr(hand.contact, a))
    assert (got.contact.mu, got.contact.wear_coefficient) == (0.4, 1e-11)
    assert got.loads[0].vector.tolist() == f.tolist() and got.loads[0].waveform == "cos"
    assert got.observed[0].name == "mass 1" and got.observed[0].dofs.tolist() == [0]
    assert got.name == "chain" and got.fixed_dofs.size == 0
    np.testing.assert_array_equal(got.load_harmonics(1), hand.load_harmonics(1))


def test_3d_contact_and_fixed_dofs():
    """Two tangential DOFs per node give a 3D interface with an identity frame; fixed DOFs
    are kept sorted."""
    K = sp.diags([1.0, 2.0, 3.0, 4.0, 5.0]) * 1e5
    model = from_matrices(K, sp.eye(5),
                          contact=ContactDofs(normal_dofs=[0], tangential_dofs=[[1, 2]], mu=0.1),
                          fixed_dofs=[4, 3], observed={"pair": [1, 2]})
    assert model.dim == 3 and model.contact.dofs.tolist() == [[0, 1, 2]]
    np.testing.assert_array_equal(model.contact.frame[0], np.eye(3))
    assert model.fixed_dofs.tolist() == [4, 3] and model.free_dofs().tolist() == [0, 1, 2]
    assert model.observed[0].dofs.tolist() == [1, 2]


def test_matrix_market_round_trip(tmp_path):
    """scipy.io.mmwrite -> read_matrix_market: the same sparse matrix (exact) and a vector
    written as a column comes back as a 1-D array; shape checks."""
    K, _ = chain()
    scipy.io.mmwrite(tmp_path / "K.mtx", sp.coo_matrix(K))
    scipy.io.mmwrite(tmp_path / "f.mtx", np.array([[1.0], [2.0], [3.0]]))
    Kr = read_matrix_market(tmp_path / "K.mtx", shape=(3, 3))
    assert sp.issparse(Kr) and abs(Kr - K).max() == 0.0
    f = read_matrix_market(tmp_path / "f.mtx", shape=(3,))
    assert f.tolist() == [1.0, 2.0, 3.0]
    with pytest.raises(InputError, match=r"holds shape \(3, 3\); expected \(4, 4\)"):
        read_matrix_market(tmp_path / "K.mtx", shape=(4, 4))
    with pytest.raises(InputError, match="does not exist"):
        read_matrix_market(tmp_path / "nope.mtx")
    (tmp_path / "bad.mtx").write_text("%%MatrixMarket matrix coordinate real general\n3 3\n")
    with pytest.raises(InputError, match="cannot read Matrix Market file"):
        read_matrix_market(tmp_path / "bad.mtx")


def test_damping_record_of_user_matrices():
    """Damping(C, rayleigh_mass=a, rayleigh_stiffness=b) gives C + a M + b K (the definition,
    written out with the chain's matrices: exact up to the order of three additions, 1e-15
    relative); a prescribed normal load without normal DOFs adds one undamped DOF per node;
    from_mesh refuses the matrices (its damping is the factors)."""
    K, M = chain()
    C0 = np.diag([0.1, 0.0, 0.2])
    a, b = 3.0, 1e-5
    got = build(damping=dict(C=C0, rayleigh_mass=a, rayleigh_stiffness=b)).C.toarray()
    np.testing.assert_allclose(got, C0 + a * M + b * K, rtol=1e-15, atol=0)
    padded = from_matrices(K, M, contact=ContactDofs(normal_dofs=None, tangential_dofs=[2],
                                                     mu=0.3, normal_load=1.0),
                           damping=Damping(rayleigh_stiffness=b, loss_factor=0.02))
    assert padded.K.shape == (4, 4)
    np.testing.assert_allclose(padded.C.toarray()[:3, :3], b * K, rtol=1e-15, atol=0)
    assert not padded.C.toarray()[3].any() and not padded.D.toarray()[3].any()
    from fretwear.model.build import ContactSpec, Material, from_mesh
    from fretwear.model.mesh import rectangle

    with pytest.raises(InputError, match="matrices C and D are for user matrices"):
        from_mesh(rectangle(0.1, 0.01, 4, 1), Material(2e11, 0.3),
                  damping=Damping(C=np.eye(20)), contact=ContactSpec("bottom", mu=0.3))
    with pytest.raises(InputError, match="expected a ContactDofs"):
        from_matrices(K, M, contact=dict(normal_dofs=[1], tangential_dofs=[2], mu=0.3))


# --------------------------------------------------------------------------------------------
# bad inputs
# --------------------------------------------------------------------------------------------
def build(K=None, M=None, *, damping=None, loads=(), fixed_dofs=(), **contact):
    """The chain with a contact node on DOFs [1, 2] (mu = 0.3) and ``contact`` fields
    changed."""
    K0, M0 = chain()
    args = dict(normal_dofs=[1], tangential_dofs=[2], mu=0.3) | contact
    return from_matrices(K0 if K is None else K, M0 if M is None else M,
                         contact=ContactDofs(**args), damping=None if damping is None
                         else Damping(**damping), loads=loads, fixed_dofs=fixed_dofs)


def test_mismatched_sizes():
    with pytest.raises(InputError, match=r"M has shape \(2, 2\); expected \(3, 3\) like K"):
        build(M=np.eye(2))
    with pytest.raises(InputError, match=r"K has shape \(3, 2\); expected a square matrix"):
        build(K=np.ones((3, 2)))


def test_non_symmetric_K():
    K, _ = chain()
    K[0, 1] = -1.5e6
    with pytest.raises(InputError, match=r"K is not symmetric: K\[.*\] = -1.5e\+06 but"):
        build(K=K)


def test_contact_dof_out_of_range():
    with pytest.raises(InputError, match=r"contact_normal_dofs: DOF 3 is out of range; "
                                         r"expected indices in \[0, 2\]"):
        build(normal_dofs=[3])
    with pytest.raises(InputError, match=r"DOF -1 is out of range"):
        build(tangential_dofs=[-1])


def test_other_bad_inputs():
    with pytest.raises(InputError, match="contact DOF 1 is listed more than once"):
        build(tangential_dofs=[1])
    with pytest.raises(InputError, match="DOF 2 is both a contact DOF and a fixed DOF"):
        build(fixed_dofs=[2])
    with pytest.raises(InputError, match="contact_normal_dofs is empty"):
        build(normal_dofs=[], tangential_dofs=[])
    with pytest.raises(InputError, match=r"shape \(1, 3\); expected \(1,\) in 2D or \(1, 2\)"):
        build(tangential_dofs=[[0, 2, 2]])
    with pytest.raises(InputError, match="either D or loss_factor"):
        build(damping=dict(D=np.eye(3), loss_factor=0.1))
    for eta in (1e300, -0.1, float("nan")):  # the bound of case files and Damping: [0, 10]
        with pytest.raises(InputError, match=r"loss_factor = .*; expected a value in \[0, 10\]"):
            build(damping=dict(loss_factor=eta))
    with pytest.raises(InputError, match="normal_sign"):
        build(normal_sign=2)
    with pytest.raises(InputError, match="area: 0; expected values > 0"):
        build(area=0.0)
    with pytest.raises(InputError, match=r"mu = -1; expected a finite value >= 0"):
        build(mu=-1)
    with pytest.raises(InputError, match=r"load 'f': vector of shape \(2,\)"):
        build(loads=[Load(np.ones(2), name="f")])


def test_singular_stiffness_is_refused():
    """Mass 1 and 2 joined by k2 only, no ground spring, contact on the massless DOF 2:
    nothing but friction holds DOFs 0 and 1."""
    K = np.array([[k2, -k2, 0.0], [-k2, k2, 0.0], [0.0, 0.0, k3]])
    with pytest.raises(InputError, match=r"singular .* DOFs \[0, 1\] can move with nothing to "
                                         r"hold them but friction"):
        build(K=K, normal_dofs=[2], tangential_dofs=[1])
    with pytest.raises(InputError, match=r"DOF\(s\) \[0\] have no stiffness"):
        build(K=np.diag([0.0, 1.0, 1.0]))


# --- refused matrices (references: matrices whose eigenvalues are known by construction) ---
def _chain(n=6, k=1.0):
    """A chain of unit springs held at both ends: positive definite (its eigenvalues are
    2 k (1 - cos(j pi / (n + 1))) > 0)."""
    return sp.diags([-k * np.ones(n - 1), 2 * k * np.ones(n), -k * np.ones(n - 1)], [-1, 0, 1])


def _contact_kw():
    return dict(contact=ContactDofs(normal_dofs=[0], tangential_dofs=[1], mu=0.3))


def test_indefinite_stiffness_is_refused_with_its_eigenvalue():
    """The chain with its first spring's coupling set to -3 holds the block [[2, -3], [-3, 2]]
    (eigenvalue -1): indefinite with a positive diagonal, so the diagonal test alone would
    let it through. The expected eigenvalue comes from numpy's dense eigvalsh."""
    K = _chain().tolil()
    K[0, 1] = K[1, 0] = -3.0
    K = K.tocsr()
    lam = np.linalg.eigvalsh(K.toarray())[0]
    assert lam < 0 and np.all(K.diagonal() >= 0)
    with pytest.raises(InputError, match=rf"K is indefinite: .*smallest eigenvalue is "
                                         rf"{lam:.4g}"):
        from_matrices(K, sp.identity(6), **_contact_kw())


def test_indefinite_mass_is_refused():
    M = sp.csr_matrix(np.array([[1.0, 2.0], [2.0, 1.0]]))  # eigenvalues 3 and -1
    K = sp.csr_matrix(np.array([[2.0, -1.0], [-1.0, 2.0]]))
    with pytest.raises(InputError, match=r"M is indefinite: .*smallest eigenvalue is -1\b"):
        from_matrices(K, M, **_contact_kw())


@pytest.mark.parametrize("which", ["C", "D"])
def test_damping_that_feeds_energy_in_is_refused(which):
    K = sp.csr_matrix(np.array([[2.0, -1.0], [-1.0, 2.0]]))
    bad = -0.01 * sp.identity(2)  # x^T C x < 0 for every x: an energy source
    with pytest.raises(InputError, match=rf"{which} is indefinite.*no energy source"):
        from_matrices(K, sp.identity(2), damping=Damping(**{which: bad}), **_contact_kw())


def test_gyroscopic_damping_is_accepted():
    """A skew-symmetric part does no work (x^T G x = 0): only the symmetric part counts."""
    K = sp.csr_matrix(np.array([[2.0, -1.0], [-1.0, 2.0]]))
    C = sp.csr_matrix(np.array([[0.1, 1.0], [-1.0, 0.1]]))
    from_matrices(K, sp.identity(2), damping=Damping(C=C), **_contact_kw())


def test_sparse_inertia_counts_the_negative_eigenvalues():
    """Above the dense limit the count comes from the LDL^T pivots (Sylvester's law of
    inertia). Reference: the chain's eigenvalues 2 - 2 cos(j pi / (n + 1)) in closed form;
    shifted by -0.7 (no leading minor is zero, so no pivoting), exactly those below 0.7 are
    negative."""
    from fretwear.model.matrices import negative_eigenvalues

    n = 2500
    j = np.arange(1, n + 1)
    lam = 2 - 2 * np.cos(j * np.pi / (n + 1))
    assert negative_eigenvalues((_chain(n) - 0.7 * sp.identity(n)).tocsr(), 0.0) == int(
        np.sum(lam < 0.7))
    assert negative_eigenvalues(_chain(n).tocsr(), 0.0) == 0


def test_large_indefinite_stiffness_is_refused():
    """A chain of 2500 DOFs with one coupling flipped to -3 ([[2, -3], [-3, 2]] has the
    eigenvalue -1): refused through the sparse path."""
    n = 2500
    K = _chain(n).tolil()
    K[0, 1] = K[1, 0] = -3.0
    with pytest.raises(InputError, match="K is indefinite"):
        from_matrices(K.tocsr(), sp.identity(n), **_contact_kw())


def test_pattern_only_matrix_market_file_is_refused(tmp_path):
    path = tmp_path / "K.mtx"
    path.write_text("%%MatrixMarket matrix coordinate pattern general\n2 2 2\n1 1\n2 2\n")
    with pytest.raises(InputError, match="pattern only"):
        read_matrix_market(path)


def test_matrix_market_header_too_large_for_the_machine_is_refused(tmp_path):
    """The header alone says 1e9 x 1e9 with 1e12 entries: refused before reading."""
    path = tmp_path / "K.mtx"
    path.write_text("%%MatrixMarket matrix coordinate real general\n"
                    "1000000000 1000000000 1000000000000\n1 1 1.0\n")
    with pytest.raises(InputError, match=r"needs about .* GiB of memory; this machine has"):
        read_matrix_market(path)
