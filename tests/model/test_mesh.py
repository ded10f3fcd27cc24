"""Mesh generators and mesh import (fretwear.model.mesh).

The references here are geometric facts that do not depend on the code under test: node
coordinates of a uniform grid, signed areas/volumes computed from coordinates, the outward
normals of the faces of a box, and the content of meshes written by meshio itself or by hand.
Integer data (connectivity, node numbers) are compared exactly; coordinates to 1e-12
relative because they come from ``linspace`` and a text round trip (``%.16e`` in Gmsh).
"""

from pathlib import Path

import meshio
import numpy as np
import pytest

from fretwear.errors import InputError
from fretwear.model.mesh import box, facet_normals, read, rectangle

DATA = Path(__file__).parents[1] / "data"


def facet_set(facets):
    """Facets as a set of sorted node tuples (orientation-free comparison)."""
    return {tuple(sorted(f)) for f in np.asarray(facets).tolist()}


def signed_areas(points, cells):
    x, y = points[cells][..., 0], points[cells][..., 1]
    return 0.5 * np.sum(x * np.roll(y, -1, 1) - np.roll(x, -1, 1) * y, axis=1)


# --------------------------------------------------------------------------------------------
def test_rectangle_layout():
    """A 4x2 grid on [1, 3] x [2, 3]: coordinates, counter-clockwise cells, boundaries ordered
    counter-clockwise around the body with outward normals, node sets and corners."""
    m = rectangle(2.0, 1.0, 4, 2, origin=(1.0, 2.0))
    assert m.cell_type == "quad" and m.dim == 2
    assert m.points.shape == (15, 2) and m.cells.shape == (8, 4)
    np.testing.assert_allclose(m.points[7], [1.0 + 2 * 0.5, 2.0 + 0.5], rtol=1e-12)
    # every cell counter-clockwise with area 0.5 x 0.5
    np.testing.assert_allclose(signed_areas(m.points, m.cells), 0.25, rtol=1e-12)
    expected_normal = {"bottom": (0, -1), "right": (1, 0), "top": (0, 1), "left": (-1, 0)}
    for name, n in expected_normal.items():
        f = m.boundaries[name]
        np.testing.assert_allclose(facet_normals(m, f), np.tile(n, (len(f), 1)), atol=1e-12)
        assert np.all(f[1:, 0] == f[:-1, 1]), f"{name} edges are not chained"
    assert m.boundaries["bottom"][0, 0] == 0 and m.boundaries["top"][0, 0] == 14
    np.testing.assert_array_equal(m.node_sets["bottom"], [0, 1, 2, 3, 4])
    np.testing.assert_array_equal(m.node_sets["top"], [10, 11, 12, 13, 14])
    np.testing.assert_array_equal(m.node_sets["left"], [0, 5, 10])
    np.testing.assert_array_equal(m.node_sets["right"], [4, 9, 14])
    corners = {k: m.points[m.node_sets[k][0]].tolist() for k in
               ("bottom_left", "bottom_right", "top_left", "top_right")}
    assert corners == {"bottom_left": [1, 2], "bottom_right": [3, 2], "top_left": [1, 3],
                       "top_right": [3, 3]}


def test_box_layout():
    """A 2x3x1 box: positive hexahedron volumes (tetra split of each hex from coordinates),
    faces with the outward normal of the box, face node sets."""
    m = box(1.0, 3.0, 0.5, 2, 3, 1)
    assert m.cell_type == "hexahedron" and m.points.shape == (3 * 4 * 2, 3)
    assert m.cells.shape == (6, 8)
    p = m.points[m.cells]
    # VTK hexahedron: volume of the tetra (0, 1, 3, 4) at the first corner is positive
    vol = np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 3] - p[:, 0]), p[:, 4] - p[:, 0])
    np.testing.assert_allclose(vol, 0.5 * 1.0 * 0.5, rtol=1e-12)
    axes = {"x": 0, "y": 1, "z": 2}
    for name, f in m.boundaries.items():
        n = np.zeros(3)
        n[axes[name[0]]] = -1.0 if name.endswith("min") else 1.0
        np.testing.assert_allclose(facet_normals(m, f), np.tile(n, (len(f), 1)), atol=1e-12)
        coord = m.points[m.node_sets[name], axes[name[0]]]
        assert np.ptp(coord) == 0.0
    assert len(m.boundaries["zmin"]) == 6 and len(m.boundaries["xmax"]) == 3
    assert len(m.node_sets["ymin"]) == 3 * 2


@pytest.mark.parametrize("args, word", [((0.0, 1.0, 2, 2), "length"),
                                        ((1.0, 1.0, 0, 2), "nx"),
                                        ((1.0, 1.0, 2, 2.5), "ny")])
def test_rectangle_bad_arguments(args, word):
    with pytest.raises(InputError, match=word):
        rectangle(*args)


# --------------------------------------------------------------------------------------------
# meshio round trips
# --------------------------------------------------------------------------------------------
def to_meshio(mesh, vertex_sets=()):
    """A meshio mesh with one Gmsh entity + physical group per boundary and per vertex set.

    Every node is given the entity of the lowest dimension it belongs to (as Gmsh does), so
    the Gmsh 4.1 writer can build its $Entities section.
    """
    dim = mesh.dim
    facet_type = {"quad": "line", "triangle": "line", "hexahedron": "quad",
                  "tetra": "triangle"}[mesh.cell_type]
    points = np.column_stack([mesh.points, np.zeros(len(mesh.points))]) if dim == 2 \
        else mesh.points
    cells = [(mesh.cell_type, mesh.cells)]
    phys, geo = [np.full(len(mesh.cells), 1)], [np.full(len(mesh.cells), 1)]
    field_data = {"body": np.array([1, dim])}
    dim_tags = np.tile([dim, 1], (len(points), 1))
    for k, (name, facets) in enumerate(mesh.boundaries.items()):
        cells.append((facet_type, facets))
        phys.append(np.full(len(facets), 10 + k))
        geo.append(np.full(len(facets), k + 1))
        field_data[name] = np.array([10 + k, dim - 1])
        dim_tags[np.unique(facets)] = [dim - 1, k + 1]
    for k, name in enumerate(vertex_sets):
        nodes = mesh.node_sets[name]
        cells.append(("vertex", nodes[:, None]))
        phys.append(np.full(len(nodes), 100 + k))
        geo.append(np.full(len(nodes), k + 1))
        field_data[name] = np.array([100 + k, 0])
        dim_tags[nodes] = [0, k + 1]
    return meshio.Mesh(points, cells, point_data={"gmsh:dim_tags": dim_tags},
                       cell_data={"gmsh:physical": phys, "gmsh:geometrical": geo},
                       field_data=field_data)


def assert_same_mesh(got, ref, vertex_sets=()):
    """Same mesh up to a renumbering of the nodes (Gmsh 4.1 files group nodes by entity)."""
    assert got.cell_type == ref.cell_type
    assert got.points.shape == ref.points.shape
    key = {tuple(np.round(p, 9)): i for i, p in enumerate(ref.points.tolist())}
    to_ref = np.array([key[tuple(np.round(p, 9))] for p in got.points.tolist()])
    np.testing.assert_allclose(got.points, ref.points[to_ref], rtol=1e-12, atol=1e-15)
    assert facet_set(to_ref[got.cells]) == facet_set(ref.cells)
    assert set(got.boundaries) == set(ref.boundaries)
    for name, f in ref.boundaries.items():
        assert facet_set(to_ref[got.boundaries[name]]) == facet_set(f)
        # read() orients facets outward like the generators do (each face here is flat)
        n_ref = facet_normals(ref, f).mean(axis=0)
        np.testing.assert_allclose(facet_normals(got, got.boundaries[name]),
                                   np.tile(n_ref, (len(f), 1)), atol=1e-12)
        np.testing.assert_array_equal(np.sort(to_ref[got.node_sets[name]]), np.unique(f))
    for name in vertex_sets:
        np.testing.assert_array_equal(np.sort(to_ref[got.node_sets[name]]),
                                      ref.node_sets[name])


@pytest.mark.parametrize("fmt", ["gmsh22", "gmsh"])
@pytest.mark.parametrize("binary", [False, True])
def test_gmsh_round_trip_2d(tmp_path, fmt, binary):
    """rectangle -> meshio -> .msh (v2.2 and v4.1, ASCII and binary) -> read(): the same
    points, cells, boundaries (as facet sets, oriented outward) and node sets."""
    ref = rectangle(0.1, 0.01, 6, 2)
    path = tmp_path / "beam.msh"
    meshio.write(path, to_meshio(ref, ["bottom_left", "top_right"]), file_format=fmt,
                 binary=binary)
    got = read(path)
    assert_same_mesh(got, ref, ["bottom_left", "top_right"])


@pytest.mark.parametrize("fmt", ["gmsh22", "gmsh"])
def test_gmsh_round_trip_3d_hex(tmp_path, fmt):
    """box -> .msh with quad facet groups -> read(): faces and node sets recovered."""
    ref = box(1.0, 0.5, 0.5, 3, 2, 2)
    path = tmp_path / "box.msh"
    meshio.write(path, to_meshio(ref), file_format=fmt, binary=False)
    assert_same_mesh(read(path), ref)


def test_gmsh_round_trip_3d_tetra(tmp_path):
    """A tetrahedral mesh (each hex split in 6) with triangle facet groups."""
    hexes = box(1.0, 1.0, 1.0, 2, 2, 2)
    split = [[0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6], [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6]]
    tets = hexes.cells[:, split].reshape(-1, 4)
    from fretwear.model.core import Mesh

    # outer faces of the tetrahedra = faces used once; each lies on one face of the box
    faces = tets[:, [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]]].reshape(-1, 3)
    _, inv, count = np.unique(np.sort(faces, axis=1), axis=0, return_inverse=True,
                              return_counts=True)
    outer = faces[count[inv.ravel()] == 1]
    centre = hexes.points[outer].mean(axis=1)
    tris = {}
    for axis, a in enumerate("xyz"):
        tris[a + "min"] = outer[np.isclose(centre[:, axis], 0.0)]
        tris[a + "max"] = outer[np.isclose(centre[:, axis], 1.0)]
    assert sum(len(f) for f in tris.values()) == len(outer) == 6 * 8
    ref = Mesh(hexes.points, tets, "tetra", tris, {})
    path = tmp_path / "tets.msh"
    meshio.write(path, to_meshio(ref), file_format="gmsh22", binary=False)
    got = read(path)
    assert got.cell_type == "tetra" and got.cells.shape == (48, 4)
    for name, f in tris.items():
        assert facet_set(got.boundaries[name]) == facet_set(f)


def test_read_hand_written_gmsh41_fixture():
    """tests/data/square_tri_v41.msh, written by hand in the Gmsh 4.1 format: unit square of
    5 triangles around the centre, physical lines bottom (2 edges), top, left, a physical
    point "origin" and one node used by no element (dropped)."""
    m = read(DATA / "square_tri_v41.msh")
    assert m.cell_type == "triangle" and m.points.shape == (6, 2)
    np.testing.assert_allclose(np.abs(signed_areas(m.points, m.cells)).sum(), 1.0, rtol=1e-14)
    assert np.all(signed_areas(m.points, m.cells) > 0)  # made counter-clockwise
    xy = {name: sorted(map(tuple, m.points[nodes].tolist())) for name, nodes in
          m.node_sets.items()}
    assert xy["origin"] == [(0.0, 0.0)]
    assert xy["bottom"] == [(0.0, 0.0), (0.5, 0.0), (1.0, 0.0)]
    assert xy["top"] == [(0.0, 1.0), (1.0, 1.0)]
    assert xy["left"] == [(0.0, 0.0), (0.0, 1.0)]
    assert len(m.boundaries["bottom"]) == 2
    np.testing.assert_allclose(facet_normals(m, m.boundaries["bottom"]), [[0, -1]] * 2,
                               atol=1e-15)
    assert "body" not in m.boundaries  # a group of body cells is not a boundary


# --------------------------------------------------------------------------------------------
# bad files
# --------------------------------------------------------------------------------------------
def test_read_missing_file(tmp_path):
    with pytest.raises(InputError, match="does not exist"):
        read(tmp_path / "nope.msh")


def test_read_malformed_file(tmp_path):
    path = tmp_path / "bad.msh"
    path.write_text("$MeshFormat\nthis is not gmsh\n")
    with pytest.raises(InputError, match="cannot read mesh file"):
        read(path)


def test_read_mixed_cell_types(tmp_path):
    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0.0]])
    m = meshio.Mesh(pts, [("quad", np.array([[0, 1, 2, 3]])),
                          ("triangle", np.array([[1, 4, 2]]))])
    path = tmp_path / "mixed.vtu"
    meshio.write(path, m)
    with pytest.raises(InputError, match=r"\['quad', 'triangle'\].*single linear type"):
        read(path)


def test_read_quadratic_cells(tmp_path):
    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.5, 0, 0], [0.5, 0.5, 0],
                    [0, 0.5, 0.0]])
    path = tmp_path / "quadratic.vtu"
    meshio.write(path, meshio.Mesh(pts, [("triangle6", np.array([[0, 1, 2, 3, 4, 5]]))]))
    with pytest.raises(InputError, match="triangle6"):
        read(path)


def test_read_2d_out_of_plane(tmp_path):
    pts = np.array([[0, 0, 1.0], [1, 0, 1.0], [0, 1, 1.0]])
    path = tmp_path / "tilted.vtu"
    meshio.write(path, meshio.Mesh(pts, [("triangle", np.array([[0, 1, 2]]))]))
    with pytest.raises(InputError, match="plane z = 0"):
        read(path)


def test_read_wrong_facet_type(tmp_path):
    """A group of triangles on a hexahedral mesh cannot be a boundary."""
    ref = box(1.0, 1.0, 1.0, 1, 1, 1)
    mm = to_meshio(ref)
    f = ref.boundaries["zmin"]
    mm.cells.append(meshio.CellBlock("triangle", f[:, :3]))
    mm.cell_data["gmsh:physical"].append(np.array([99]))
    mm.cell_data["gmsh:geometrical"].append(np.array([1]))
    mm.field_data["tri"] = np.array([99, 2])
    path = tmp_path / "hex_tri.msh"
    meshio.write(path, mm, file_format="gmsh22", binary=False)
    with pytest.raises(InputError, match="group 'tri' holds \\['triangle'\\] facets"):
        read(path)


# --- element validity (reference: hand-made elements whose validity is known by geometry) ---
def test_every_structured_element_is_valid():
    """rectangle() and box() make positively oriented elements: every corner Jacobian is > 0
    (a unit square element has 1 at each corner: 1 = cross product of two unit edges)."""
    from fretwear.model.mesh import check_cells, corner_jacobians

    for m in (rectangle(2.0, 1.0, 4, 2), box(1.0, 2.0, 3.0, 2, 2, 2)):
        check_cells(m)
        assert np.all(corner_jacobians(m.points, m.cells, m.cell_type) > 0)
    unit = rectangle(1.0, 1.0, 1, 1)
    assert np.allclose(corner_jacobians(unit.points, unit.cells, unit.cell_type), 1.0,
                       rtol=1e-14)


def test_self_intersecting_quadrilateral_is_refused():
    """A bow-tie quadrilateral (two nodes swapped) has corner Jacobians of both signs."""
    from fretwear.model.core import Mesh
    from fretwear.model.mesh import check_cells

    pts = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    bowtie = Mesh(pts, np.array([[0, 1, 3, 2]]), "quad")
    with pytest.raises(InputError, match=r"quad element 0 with nodes \[0, 1, 3, 2\] is "
                                         r"inverted or self-intersecting"):
        check_cells(bowtie)


def test_inverted_hexahedron_is_refused():
    """A hexahedron with its top and bottom faces swapped is inverted (negative volume)."""
    from fretwear.model.core import Mesh
    from fretwear.model.mesh import check_cells

    m = box(1.0, 1.0, 1.0, 1, 1, 1)
    flipped = Mesh(m.points, m.cells[:, [4, 5, 6, 7, 0, 1, 2, 3]], "hexahedron")
    with pytest.raises(InputError, match="hexahedron element 0 .* inverted"):
        check_cells(flipped)


@pytest.mark.parametrize("value", ["nan", "inf", "-inf"])
def test_mesh_file_with_non_finite_coordinates_is_refused(tmp_path, value):
    text = (DATA / "square_tri_v41.msh").read_text()
    bad = text.replace("\n0.25 0.75 0\n", f"\n{value} 0.75 0\n", 1)
    assert bad != text
    path = tmp_path / "bad.msh"
    path.write_text(bad)
    with pytest.raises(InputError, match="expected finite coordinates"):
        read(path)


def test_user_mesh_with_non_finite_coordinates_is_refused():
    from fretwear.model.core import Mesh
    from fretwear.model.mesh import check_cells

    m = rectangle(1.0, 1.0, 2, 2)
    m.points[4, 1] = np.nan
    with pytest.raises(InputError, match=r"node 4 has coordinates .*expected finite"):
        check_cells(Mesh(m.points, m.cells, m.cell_type))


# --- magnitudes and sizes (reference: the documented ranges of fretwear.limits) ------------
@pytest.mark.parametrize("length", [1e-300, 1e300, 1e-10, 2e5])
def test_lengths_outside_the_documented_range_are_refused(length):
    with pytest.raises(InputError, match=r"length = .* m: expected a magnitude in \[1e-09, "
                                         r"100000\] m"):
        rectangle(length, 1.0, 2, 2)


def test_lengths_at_the_ends_of_the_range_are_accepted():
    rectangle(1e-9, 1e-9, 1, 1)
    rectangle(1e5, 1e5, 1, 1)


def test_a_mesh_too_large_for_the_machine_is_refused_before_it_is_made():
    with pytest.raises(InputError, match=r"a mesh of 1e\+09 hexahedra needs about .* GiB of "
                                         r"memory; this machine has"):
        box(1.0, 1.0, 1.0, 1000, 1000, 1000)
