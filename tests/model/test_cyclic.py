"""The sector model: matching of the cyclic boundaries, the reduction ``U = T_k q`` and the
whole disk assembled from the sector.

References: the geometry itself (a node turned by 2 pi / N lands on its match), the
definition of ``T_k`` (the right boundary is the left one turned and phased, checked DOF by
DOF), and the disk assembled independently (a real symmetric matrix whose sector-0 rows,
applied to a travelling wave built from ``T_k q``, give ``T_k^H`` of the sector's forces).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from helpers.cyclic import sector_model

from fretwear.errors import InputError
from fretwear.model.core import Mesh
from fretwear.model.cyclic import (
    cyclic_sector,
    harmonic_index,
    harmonic_model,
    rotation_matrix,
    sector_maps,
    transform,
    whole_disk,
)


def test_boundaries_match_by_the_rotation():
    """Every right node is its left node turned by 2 pi / N about the axis (to rounding)."""
    sector, model = sector_model(8)
    R = rotation_matrix(sector.axis, sector.angle, 2)
    assert np.allclose(sector.left_coords @ R.T, sector.right_coords, atol=1e-15)
    assert np.allclose(sector.rotation, R)
    assert sector.left_dofs.shape == (4, 2)


def test_rotation_3d_turns_about_the_axis():
    """Rodrigues' formula against the rotation about z, and the axis itself is left fixed."""
    Rz = rotation_matrix((0.0, 0.0, 1.0), 0.3, 3)
    assert np.allclose(Rz[:2, :2], rotation_matrix((0.0, 0.0, 1.0), 0.3, 2), atol=1e-15)
    a = np.array([1.0, 2.0, 2.0]) / 3.0
    R = rotation_matrix(a, 1.1, 3)
    assert np.allclose(R @ a, a, atol=1e-15)
    assert np.allclose(R @ R.T, np.eye(3), atol=1e-15)


def test_harmonic_index_wraps_and_takes_negative_orders():
    """k = n EO mod N, in 0..N-1 (a negative EO is the wave travelling the other way)."""
    assert harmonic_index(np.arange(4), 3, 8).tolist() == [0, 3, 6, 1]
    assert harmonic_index(np.arange(4), -3, 8).tolist() == [0, 5, 2, 7]
    assert harmonic_index(2, 11, 8) == 6


def test_transform_puts_the_turned_and_phased_left_boundary_on_the_right():
    """``(T_k q)[right] = e^{i k alpha} R (T_k q)[left]`` for a random ``q``; the kept DOFs are
    ``q`` itself."""
    sector, model = sector_model(8)
    k = 3
    T = transform(sector, k)
    q = np.random.default_rng(0).normal(size=T.shape[1]) + 0j
    U = T @ q
    want = np.exp(1j * k * sector.angle) * U[sector.left_dofs] @ sector.rotation.T
    assert np.allclose(U[sector.right_dofs], want, rtol=0, atol=1e-14)
    assert np.array_equal(U[sector.kept_dofs()], q)


def test_harmonic_model_is_hermitian_and_real_at_0_and_half():
    """``T_k^H K T_k`` is Hermitian; real for k = 0 and N/2 (phases +-1)."""
    sector, _ = sector_model(8)
    for k in range(8):
        red, _ = harmonic_model(sector, k)
        K = red.K.toarray()
        assert np.allclose(K, K.conj().T, rtol=0, atol=1e-9 * np.abs(K).max())
        assert np.iscomplexobj(K) == (k not in (0, 4))


def test_disk_rows_of_a_travelling_wave_are_the_sector_forces():
    """Assembly check, independent of ``T_k^H``: the disk's stiffness applied to the wave
    ``U_j = e^{i k j alpha} T_k q`` (each sector in the disk's axes), read on sector 0's kept
    DOFs, equals ``T_k^H K T_k q`` (the force balance of the kept DOFs, neighbours included)."""
    sector, model = sector_model(8)
    A, nd = sector_maps(sector)
    keep = sector.kept_dofs()
    for k in (0, 1, 3, 4):
        red, T = harmonic_model(sector, k)
        q = np.random.default_rng(k).normal(size=T.shape[1]) * (1 + 0.5j)
        Us = T @ q
        Ud = sum(Aj[:, keep] @ (np.exp(1j * k * j * sector.angle) * q)
                 for j, Aj in enumerate(A))
        assert np.allclose(A[0].T @ Ud, Us, rtol=0, atol=1e-12 * np.abs(Us).max())
        disk = whole_disk(sector)
        f_disk = (A[0].T @ (disk.K @ Ud))[keep]
        f_sector = red.K @ q
        assert np.allclose(f_disk, f_sector, rtol=0, atol=1e-9 * np.abs(f_sector).max())


def test_whole_disk_has_every_sector():
    """N copies: DOFs N nq, contact nodes N nc, sector j's contact frames turned by j alpha."""
    sector, model = sector_model(6)
    disk = whole_disk(sector, engine_order=2)
    nq = sector.kept_dofs().size
    assert disk.ndof == 6 * nq
    nc = model.contact.n_nodes
    assert disk.contact.n_nodes == 6 * nc
    Q = sector.turn(2)
    assert np.allclose(disk.contact.frame[2 * nc:3 * nc], model.contact.frame @ Q.T)
    assert len(disk.loads) == 6 * len(model.loads)


def test_unmatched_node_says_its_distance():
    """A left node moved off its image: one InputError naming the distance."""
    sector, model = sector_model(8)
    mesh = model.mesh
    pts = mesh.points.copy()
    pts[mesh.node_sets["left"][2]] *= 1.001
    moved = dataclasses.replace(model, mesh=Mesh(pts, mesh.cells, mesh.cell_type,
                                                  mesh.boundaries, mesh.node_sets))
    with pytest.raises(InputError, match=r"left node 2 .* is 0.000\d+ m from the nearest"):
        cyclic_sector(moved, 8, "left", "right")


def test_bad_inputs_are_refused_in_one_line():
    """Swapped boundaries (with the hint), a wrong count, a non-unit axis, an unknown name."""
    _, model = sector_model(8)
    with pytest.raises(InputError, match="swap left and right"):
        cyclic_sector(model, 8, "right", "left")
    with pytest.raises(InputError, match="from the nearest right node"):
        cyclic_sector(model, 7, "left", "right")
    with pytest.raises(InputError, match="unit vector"):
        cyclic_sector(model, 8, "left", "right", axis=(0.0, 0.0, 2.0))
    with pytest.raises(InputError, match="n_sectors"):
        cyclic_sector(model, 1, "left", "right")
    with pytest.raises(InputError, match="no boundary or node set"):
        cyclic_sector(model, 8, "lft", "right")
    with pytest.raises(InputError, match="both the left and the right"):
        cyclic_sector(model, 8, "left", "left")


def test_neighbour_contact_pairs_a_face_with_the_next_sectors_face():
    """Each node of face A is paired with the node of face B that lands on it turned by
    2 pi / N; in the disk its partner is the next sector's node (same position)."""
    sector, model = sector_model(8, slit=True)
    c = model.contact
    nb = sector.neighbour_nodes()
    assert nb.sum() == 3 and not nb[~(c.interface_index() == 1)].any()
    pts = model.mesh.points
    b = np.asarray(c.partner_ids)[nb]
    turned = pts[b] @ sector.rotation.T
    assert np.allclose(turned, c.coords[nb], rtol=0, atol=1e-15)
    disk = whole_disk(sector, 1)
    A, _ = sector_maps(sector)
    first = np.flatnonzero(nb)[0]
    y = np.zeros(model.ndof)
    y[c.partner_dofs[first]] = 1.0  # the partner's image in sector 0, put in sector 1
    assert set(np.flatnonzero(A[1] @ y)) == set(disk.contact.partner_dofs[first])
    assert set(np.flatnonzero(A[1] @ y)).isdisjoint(np.flatnonzero(A[0] @ y))


def test_neighbour_contact_refuses_a_face_paired_with_itself():
    """A damper pairing a boundary with itself, or faces that do not match: one line."""
    from fretwear.model.build import ContactSpec
    from fretwear.model.cyclic import neighbour_contact

    base, _ = sector_model(8, slit=True)
    with pytest.raises(InputError, match="pairs a boundary with another"):
        neighbour_contact(base, ContactSpec("slit_a", mu=0.3, partner="slit_a", name="x"))
    with pytest.raises(InputError, match="swap left and right|from the nearest"):
        neighbour_contact(base, ContactSpec("slit_b", mu=0.3, partner="slit_a", name="x"))


def test_sector_of_user_matrices_from_dofs():
    """The entry for models without a mesh (DOFs and positions of the boundary nodes, any
    order) gives the same matched sector as the mesh entry."""
    from fretwear.model.cyclic import cyclic_sector_from_dofs

    sector, model = sector_model(8)
    flip = np.arange(sector.left_dofs.shape[0])[::-1]  # the right nodes listed backwards
    other = cyclic_sector_from_dofs(
        model, 8, (sector.left_dofs, sector.left_coords),
        (sector.right_dofs[flip], sector.right_coords[flip]), tolerance=1e-9)
    assert np.array_equal(other.right_dofs, sector.right_dofs)
    assert np.allclose(transform(other, 3).toarray(), transform(sector, 3).toarray())


def _wedge_damper_sector(n_sectors: int = 8, seat: bool = True):
    """``(mesh, seat spec, neighbour spec)``: a 2D annulus sector (0.1 <= r <= 0.2 m, hub
    held) with a tooth (0.2 <= r <= 0.22 m, 0 <= theta <= alpha / 4) and a separate block
    (the damper, 0.2 <= r <= 0.22 m, alpha / 2 <= theta <= 5 alpha / 4) that sits on the
    disk's rim (one edge, node to node) and whose far face touches the next sector's tooth.
    Nothing but these two contacts holds the block: a wedge damper between two platforms.
    Without ``seat`` the rim touches a rigid casing instead and the block lies on nothing."""
    from fretwear.model.build import ContactSpec
    from fretwear.model.mesh import join, rectangle

    a = 2 * np.pi / n_sectors

    def polar(p):
        return np.column_stack([p[:, 0] * np.cos(p[:, 1]), p[:, 0] * np.sin(p[:, 1])])

    r = rectangle(0.12, a, 6, 4, origin=(0.1, 0.0))  # node i + 7 j: r index i, theta j
    keep = [c for c, cell in enumerate(r.cells) if c % 6 < 5 or c // 6 == 0]
    cells = r.cells[keep]
    used = np.unique(cells)
    new = np.full(r.points.shape[0], -1)
    new[used] = np.arange(used.size)
    rr, tt = r.points[:, 0], r.points[:, 1]

    def node(i, j):
        return int(new[i + 7 * j])

    disk = Mesh(polar(r.points[used]), new[cells], "quad",
                {"hub": new[r.boundaries["left"]], "seat": np.array([[node(5, 2), node(5, 3)]]),
                 "tooth": np.array([[node(5, 1), node(6, 1)]])},
                {"left": new[np.flatnonzero((tt < 1e-12) & (rr < 0.2 + 1e-12))],
                 "right": new[np.flatnonzero((tt > a - 1e-12) & (rr < 0.2 + 1e-12))],
                 "hub": new[np.flatnonzero(rr < 0.1 + 1e-12)]})
    d = rectangle(0.02, 0.75 * a, 1, 3, origin=(0.2, 0.5 * a))  # node i + 2 j
    damper = Mesh(polar(d.points), d.cells, "quad",
                  {"seat": np.array([[2, 0]]), "face": np.array([[6, 7]])}, {})
    mesh = join(("disk", disk), ("damper", damper))
    specs = [ContactSpec("damper.seat", mu=0.3, partner="disk.seat", name="seat") if seat
             else ContactSpec("disk.seat", mu=0.3, name="rim")]  # the block on nothing
    return mesh, specs, ContactSpec("damper.face", mu=0.3, partner="disk.tooth", name="next")


def _disk_free_motions(sector) -> int:
    """The zero-energy motions of the whole disk assembled from ``sector``
    (:func:`whole_disk`) with every contact held along its normal (in the relative
    coordinates of its pairs, fretwear.model.interfaces.relative_model) and the fixed DOFs
    held: the dimension of the null space of ``K`` on the DOFs that satisfy those
    constraints (dense; the eigenvalues below 1e-9 of the largest)."""
    import scipy.linalg as sla

    from fretwear.model.interfaces import relative_model

    disk = whole_disk(sector)
    rel, _ = relative_model(disk)
    c = rel.contact
    G = np.zeros((c.n_nodes + len(rel.fixed_dofs), rel.ndof))
    for n in range(c.n_nodes):
        G[n, c.dofs[n]] = c.frame[n, 0]
    G[c.n_nodes + np.arange(len(rel.fixed_dofs)), rel.fixed_dofs] = 1.0
    Z = sla.null_space(G)
    lam = np.linalg.eigvalsh(Z.T @ rel.K.toarray() @ Z)
    return int(np.sum(lam < 1e-9 * lam.max()))


@pytest.mark.parametrize("seat", [True, False])
def test_a_damper_held_by_its_neighbour_contact_needs_no_spring(seat):
    """The support check sees the contact with the next sector: a block held by its seat
    on this sector and its face on the next one is held (no spring); without its seat it is
    refused. Reference: the whole disk assembled from the 8 sectors with every contact held
    along its normal has no zero-energy motion exactly when the sector check passes (one
    free motion per damper without the seat). ``from_mesh``, which checks before the
    neighbour contact exists, refuses the block."""
    from fretwear.model.build import Material, from_mesh, unchecked_from_mesh
    from fretwear.model.cyclic import neighbour_contact
    from fretwear.model.supports import Unsupported

    mesh, specs, nb = _wedge_damper_sector(8, seat)
    args = dict(supports=[("disk.hub", "all")], contact=specs, thickness=0.01)
    steel = Material(2e11, 0.3, 7800.0)
    with pytest.raises(Unsupported, match="body 'damper' can"):
        from_mesh(mesh, steel, **args)
    sector = cyclic_sector(unchecked_from_mesh(mesh, steel, **args), 8, "disk.left",
                           "disk.right")
    if seat:
        assert _disk_free_motions(neighbour_contact(sector, nb)) == 0
    else:
        with pytest.raises(Unsupported, match="body 'damper' can"):
            neighbour_contact(sector, nb)
        assert _disk_free_motions(_neighbour_unchecked(sector, nb)) == 8


def _neighbour_unchecked(sector, spec):
    """``neighbour_contact`` without its support check (the disk reference of a sector that
    the check refuses)."""
    import fretwear.model.cyclic as cyc

    keep = cyc.check_supported
    cyc.check_supported = lambda *a, **k: None
    try:
        return cyc.neighbour_contact(sector, spec)
    finally:
        cyc.check_supported = keep
