"""Models built from exported matrices (from_fe) against the model built from the mesh: a
small 2D block on a rigid flat and the shipped dovetail (both elastic bodies, two node-to-node
flanks), exported to every format with the contact, supports, loads and observed points named
by node ids (tests/helpers/fe_files.py: node id = mesh node number + 1)."""

import dataclasses

import numpy as np
import pytest
import scipy.sparse as sp
from helpers import fe_files as ff
from helpers.blocks import block

from fretwear import simulate_wear, solve_periodic
from fretwear.errors import InputError
from fretwear.hb.fourier import FourierBasis
from fretwear.model.readers import FEMatrices, NodeContact, from_fe, read_fe, write_dofmap
from fretwear.wear import WearOptions

BASIS = FourierBasis.up_to(3, 32)
F_HZ = 2000.0


@pytest.fixture(scope="module")
def mesh_model():
    """The 2D block with hysteretic damping (a D matrix to export) and a wear coefficient."""
    model = block(2, 0.01)
    model.contact.wear_coefficient = 1e-12
    return model


def _export(model, tmp_path, fmt):
    """The model's K, M, D written in ``fmt``, read back."""
    dofs = ff.dofmap_of(model)
    mats = {"K": model.K, "M": model.M, "D": model.D}
    write_dofmap(tmp_path / "dofs.txt", dofs)
    if fmt == "dmig":
        ff.write_dmig(tmp_path / "m.pch", {"KAAX": model.K, "MAAX": model.M,
                                           "K4AX": model.D}, dofs)
        return read_fe(tmp_path / "m.pch")
    if fmt == "op4":
        ff.write_op4(tmp_path / "m.op4", {"KAAX": model.K, "MAAX": model.M, "K4AX": model.D})
        return read_fe(tmp_path / "m.op4", dofmap=tmp_path / "dofs.txt")
    if fmt == "abaqus":
        ff.write_abaqus_substructure(tmp_path / "m.mtx", {
            "STIFFNESS": model.K, "MASS": model.M, "STRUCTURAL DAMPING": model.D}, dofs)
        return read_fe(tmp_path / "m.mtx")
    if fmt == "ansys-full":  # K and M only
        ff.write_ansys_full(tmp_path / "m.full", model.K, model.M, dofs)
        return read_fe(tmp_path / "m.full")
    if fmt == "abaqus-matrix-input":
        for k, A in mats.items():
            ff.write_abaqus_matrix_input(tmp_path / f"{k}.mtx", A, dofs)
        files = [tmp_path / f"{k}.mtx" for k in mats]
    else:
        write = ff.write_matrix_market if fmt == "matrix-market" else ff.write_harwell_boeing
        suffix = ".mtx" if fmt == "matrix-market" else ".rua"
        for k, A in mats.items():
            write(tmp_path / f"{k}{suffix}", A)
        files = [tmp_path / f"{k}{suffix}" for k in mats]
    return read_fe(files[0], files[1], D=files[2], format=fmt,
                   dofmap=None if fmt.startswith("abaqus") else tmp_path / "dofs.txt")


def _rebuilt(model, fe):
    return from_fe(fe, contact=ff.contacts_of(model), nodes=ff.node_table(model),
                   loads=ff.forces_of(model), fixed=ff.fixed_of(model),
                   observed=ff.observed_of(model), name=model.name)


#: relative accuracy of each format's numbers: DMIG's 16-character fields hold 10 significant
#: digits (half a unit in the last: 5e-10); the others are written with 17 (to the last bit)
DIGITS = {"dmig": 5e-10, "op4": 0.0, "abaqus": 0.0, "abaqus-matrix-input": 0.0,
          "matrix-market": 0.0, "harwell-boeing": 0.0, "ansys-full": 0.0}


@pytest.mark.parametrize("fmt", list(DIGITS))
def test_every_format_gives_the_mesh_model(mesh_model, tmp_path, fmt):
    """K, M, D to the format's digits (a .full file holds K and M only); contact DOFs,
    frames, areas, coordinates, loads and supports exactly."""
    m0 = mesh_model
    m1 = _rebuilt(m0, _export(m0, tmp_path, fmt))
    for what in ("K", "M") if fmt == "ansys-full" else ("K", "M", "D"):
        a, b = getattr(m1, what), getattr(m0, what)
        assert abs(a - b).max() <= DIGITS[fmt] * abs(b).max(), what
    c0, c1 = m0.contact, m1.contact
    np.testing.assert_array_equal(c1.dofs, c0.dofs)
    for what in ("frame", "area", "gap", "coords"):
        np.testing.assert_array_equal(getattr(c1, what), getattr(c0, what))
    np.testing.assert_array_equal(c1.node_ids, c0.dofs[:, 0] // 2 + 1)
    for a, b in zip(m1.loads, m0.loads, strict=True):
        np.testing.assert_array_equal(a.vector, b.vector)
        assert a.waveform == b.waveform
    np.testing.assert_array_equal(m1.fixed_dofs, m0.fixed_dofs)


def _ten_digits(A):
    """``A`` with every entry rounded to 10 significant digits, as DMIG's fields hold them."""
    A = A.tocsr(copy=True)
    A.data = np.array([float(f"{v:.9e}") for v in A.data])
    return A


@pytest.mark.parametrize("fmt", ["dmig", "matrix-market"])
def test_periodic_solve_and_wear_step(mesh_model, tmp_path, fmt):
    """The periodic solution (contact displacement and force harmonics) and one wear step
    (worn depths) of the model read from the files equal those of the mesh model to 1e-10
    relative. DMIG holds 10 significant digits: its model is compared with the mesh model
    whose K, M, D are rounded to 10 digits (against the unrounded one the harmonics differ by
    7e-9 of the largest, the 5e-10 rounding amplified by the conditioning of the block on its
    flat)."""
    m0 = mesh_model
    m1 = _rebuilt(m0, _export(m0, tmp_path, fmt))
    if fmt == "dmig":
        m0 = dataclasses.replace(m0, K=_ten_digits(m0.K), M=_ten_digits(m0.M),
                                 D=_ten_digits(m0.D))
    s0, s1 = (solve_periodic(m, BASIS, F_HZ, eps=1e12) for m in (m0, m1))
    assert s0.success and s1.success
    for what in ("U", "lam"):
        a, b = getattr(s1, what), getattr(s0, what)
        assert abs(a - b).max() <= 1e-10 * abs(b).max(), what
    opts = WearOptions(max_steps=1)
    w0, w1 = (simulate_wear(m, BASIS, F_HZ, options=opts).final_wear for m in (m0, m1))
    assert w0.max() > 0
    assert abs(w1 - w0).max() <= 1e-10 * w0.max()


@pytest.fixture(scope="module")
def dovetail():
    from fretwear.analyses.run import load_case
    from fretwear.examples import example_path
    from fretwear.io.case import build_model

    return build_model(load_case(example_path("dovetail-frf")))


@pytest.mark.parametrize("fmt", ["matrix-market", "harwell-boeing"])
def test_dovetail_through_scipy_files(dovetail, tmp_path, fmt):
    """The shipped dovetail (6618 DOFs, 86 pairs on two flanks, a spring, fixed base, two
    loads, an observed tip) read back from the files SciPy writes is the mesh model: same K,
    M, D (to the last bit), the same two interfaces node by node, loads, supports, observed
    DOFs; its modes and responses are therefore the same to rounding. (DMIG, OP4 and Abaqus
    are checked on the small block above; the dovetail through them, and through pyNastran's
    writers, is studies/dovetail_exports.py: docs/studies/dovetail-exports.md.)"""
    m0 = dovetail
    fe = _export(m0, tmp_path, fmt)
    m1 = _rebuilt(m0, fe)
    for what in ("K", "M", "D"):
        assert abs(getattr(m1, what) - getattr(m0, what)).max() == 0.0, what
    c0, c1 = m0.contact, m1.contact
    for what in ("dofs", "partner_dofs", "frame", "area", "gap", "interface"):
        np.testing.assert_array_equal(getattr(c1, what), getattr(c0, what))
    assert c1.names() == c0.names()
    np.testing.assert_array_equal(c1.partner_wear_nodes(), c0.partner_wear_nodes())
    np.testing.assert_array_equal(m1.fixed_dofs, m0.fixed_dofs)
    np.testing.assert_array_equal(m1.observed[0].dofs, m0.observed[0].dofs)
    np.testing.assert_array_equal(m1.observed[0].coords, m0.mesh.points[m0.observed[0].dofs[0]
                                                                          // 3])
    for a, b in zip(m1.loads, m0.loads, strict=True):
        np.testing.assert_array_equal(a.vector, b.vector)


def test_dovetail_superelement(dovetail):
    """The dovetail as a Craig-Bampton superelement: boundary = the 172 flank nodes and the
    tip (519 DOFs), 30 fixed-interface modes of the 5.9e3 interior DOFs (the base held). Its
    first three modes with sliding flanks (2.03, 3.71, 5.21 kHz) are upper bounds of the
    mesh model's within 2e-4 (measured 1.4e-6, 1.0e-5, 1.3e-4: the first fixed-interface
    mode is at 11.2 kHz); all modes kept would be exact (test_superelement.py, on a model small
    enough for a dense eigensolution)."""
    from fretwear.linear import modes
    from fretwear.model.core import Load
    from fretwear.model.readers import craig_bampton

    m0 = dovetail
    fe = FEMatrices(m0.K, m0.M, ff.dofmap_of(m0), D=m0.D)
    contact = ff.contacts_of(m0)
    boundary = np.concatenate([np.concatenate([c.nodes, c.partners]) for c in contact]
                              + [[m0.observed[0].dofs[0] // 3 + 1]])
    se = craig_bampton(fe, boundary, n_modes=30, fixed=m0.fixed_dofs)
    assert se.fe.dofs.size == 3 * 173 + 30
    loads = [Load(se.reduce(ld.vector), ld.waveform, ld.coefficients, ld.name)
             for ld in m0.loads]
    m1 = from_fe(se.fe, contact=contact, loads=loads, observed=ff.observed_of(m0))
    f0 = modes(m0, 3, interface="sliding").frequency_hz
    f1 = modes(m1, 3, interface="sliding").frequency_hz
    assert np.all(f1 >= f0 * (1 - 1e-12)) and np.all(f1 <= f0 * (1 + 2e-4))


def test_bad_input_is_one_line(mesh_model):
    """An absent node id, a missing component, a non-symmetric K, a wrong DOF map size."""
    m0 = mesh_model
    fe = FEMatrices(m0.K, m0.M, ff.dofmap_of(m0))
    contact = ff.contacts_of(m0)[0]
    bad = NodeContact(nodes=[999], mu=0.3, normal=[0.0, -1.0])
    for kw, msg in ((dict(contact=bad), "node 999 is not in the matrices' DOF map"),
                    (dict(contact=contact, observed={"p": 998}), "node 998"),
                    (dict(contact=contact, fixed=[([1], [3])]), "node 1 has no component 3")):
        with pytest.raises(InputError, match=msg) as exc:
            from_fe(fe, **kw)
        assert "\n" not in str(exc.value)
    K = m0.K.tolil()
    K[0, 1] += 1e-3 * abs(m0.K).max()
    with pytest.raises(InputError, match="K is not symmetric"):
        from_fe(FEMatrices(K.tocsr(), m0.M, fe.dofs), contact=contact)
    with pytest.raises(InputError, match="DOF map has 40 rows"):
        FEMatrices(m0.K, m0.M, fe.dofs.permuted(np.arange(40)))
    with pytest.raises(InputError, match="give either normal or frames"):
        from_fe(fe, contact=NodeContact(nodes=contact.nodes, mu=0.3))


def test_normals_give_frames(mesh_model):
    """A normal (0, -1) on the bottom gives the mesh model's frames [n, t] up to the sign of
    the tangent, and the same model otherwise."""
    m0 = mesh_model
    fe = FEMatrices(m0.K, m0.M, ff.dofmap_of(m0))
    c = ff.contacts_of(m0)[0]
    m1 = from_fe(fe, contact=NodeContact(nodes=c.nodes, mu=c.mu, normal=[0.0, -1.0],
                                         area=c.area))
    np.testing.assert_allclose(m1.contact.frame[:, 0], m0.contact.frame[:, 0], atol=1e-15)
    np.testing.assert_allclose(np.abs(m1.contact.frame[:, 1]), np.abs(m0.contact.frame[:, 1]),
                               atol=1e-15)
    assert sp.issparse(m1.K)


def test_partners_from_a_node_set_are_paired_by_position():
    """Partners given as a node set are matched to the contact nodes at their positions (the
    set lists them in another order); a partner face that does not match is one line."""
    from fretwear.model.readers import DofMap, NodeTable

    dofs = DofMap(np.repeat([1, 2, 3, 4], 2), np.tile([1, 2], 4))
    fe = FEMatrices(sp.identity(8, format="csr") * 1e6, sp.identity(8, format="csr"), dofs)
    xyz = np.array([[0.0, 0, 0], [1, 0, 0], [1, 0, 0], [0, 0, 0]])
    table = NodeTable(np.array([1, 2, 3, 4]), xyz, {"upper": np.array([1, 2]),
                                                    "lower": np.array([3, 4])})
    pair = NodeContact(nodes="upper", partners="lower", mu=0.3, normal=[0.0, -1.0])
    model = from_fe(fe, contact=pair, nodes=table)
    np.testing.assert_array_equal(model.contact.partner_ids, [4, 3])
    np.testing.assert_array_equal(model.contact.partner_dofs, [[6, 7], [4, 5]])
    table.xyz[3] = [0.5, 0.0, 0.0]
    with pytest.raises(InputError, match="node 1 has no partner at its position"):
        from_fe(fe, contact=pair, nodes=table)
