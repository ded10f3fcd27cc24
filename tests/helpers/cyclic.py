"""A small 2D sector of an annular disk (plane strain) shared by the cyclic tests: the hub
clamped, a tip strip against a rigid casing, a static radial press and a tangential
harmonic force at the tip."""

from __future__ import annotations

import numpy as np

from fretwear.model.build import ContactSpec, Damping, Material, NodalForce, from_mesh
from fretwear.model.core import Mesh
from fretwear.model.cyclic import cyclic_sector, neighbour_contact
from fretwear.model.mesh import rectangle

R_IN, R_OUT = 0.1, 0.2


def annulus_sector(n_sectors: int, nr: int = 3, nt: int = 4, slit: float | None = None) -> Mesh:
    """Quads on ``R_IN <= r <= R_OUT``, ``0 <= theta <= 2 pi / n_sectors``: boundaries
    ``hub`` (r = R_IN), ``tip`` (r = R_OUT, its two end edges left out so that no contact
    node lies on a cyclic boundary), node sets ``left`` (theta = 0), ``right`` (theta = 2 pi
    / N), ``tip_mid`` (one tip node), ``load`` (an inner node near the tip). The inner nodes
    are skewed so that the sector has no mirror symmetry and the disk no symmetry beyond its
    N sectors. ``slit`` [m]: the sectors are joined below this radius only (``left``,
    ``right``); above it their faces are boundaries ``slit_b`` (theta = 0) and ``slit_a``
    (theta = 2 pi / N), the next sector's ``slit_b`` touching ``slit_a`` (an inter-blade
    contact)."""
    m = rectangle(R_OUT - R_IN, 2 * np.pi / n_sectors, nr, nt, origin=(R_IN, 0.0))
    r, t = m.points[:, 0].copy(), m.points[:, 1].copy()
    inner = (t > 1e-12) & (t < 2 * np.pi / n_sectors - 1e-12)  # not on a cyclic boundary
    t[inner] += 0.15 * (2 * np.pi / n_sectors / nt) * ((r[inner] - R_IN) / (R_OUT - R_IN))
    pts = np.column_stack([r * np.cos(t), r * np.sin(t)])
    tip = m.boundaries["right"]  # r = R_OUT, ordered by increasing theta
    bounds = {"hub": m.boundaries["left"], "tip": tip[1:-1]}
    sets = {"left": m.node_sets["bottom"], "right": m.node_sets["top"],
            "hub": m.node_sets["left"], "tip_mid": m.node_sets["right"][[nt // 2]],
            "load": np.array([nr - 1 + (nr + 1) * (nt // 2)])}
    if slit is not None:
        x = m.points[:, 0]
        for side, name, face in (("bottom", "left", "slit_b"), ("top", "right", "slit_a")):
            sets[name] = sets[name][x[sets[name]] < slit]
            edges = m.boundaries[side]
            bounds[face] = edges[np.all(x[edges] > slit, axis=1)]
    return Mesh(pts, m.cells, "quad", bounds, sets)


def sector_model(n_sectors: int = 8, *, damping=True, mu: float = 0.3, press: float = 2e4,
                 force: float = 5e3, contact: bool = True, slit: bool = False,
                 wear: float = 0.0):
    """``(sector, model)``: the annulus sector with ``n_sectors`` sectors; ``slit``: the
    sectors joined below r = 0.14 m only, with a friction contact between neighbours above
    (an interference of 0.2 um presses them together)."""
    mesh = annulus_sector(n_sectors, nr=4 if slit else 3, slit=0.14 if slit else None)
    mid = mesh.points[mesh.node_sets["load"][0]]
    e_r = mid / np.linalg.norm(mid)
    e_t = np.array([-e_r[1], e_r[0]])
    loads = [NodalForce("load", tuple(press * e_r), "constant", name="press"),
             NodalForce("load", tuple(force * e_t), "cos", name="excitation")]
    spec = ContactSpec("tip", mu=mu, name="casing", wear_coefficient=wear,
                       gap=0.0 if contact else 1.0)
    model = from_mesh(mesh, Material(2e11, 0.3, 7800.0), thickness=0.01,
                      damping=Damping(loss_factor=0.01, rayleigh_mass=5.0) if damping else None,
                      supports=[("hub", "all")], loads=loads, contact=spec,
                      observed={"tip": "load"}, name="annulus sector")
    sector = cyclic_sector(model, n_sectors, "left", "right")
    if slit:
        sector = neighbour_contact(sector, ContactSpec("slit_a", mu=mu, partner="slit_b",
                                                       gap=-2e-7, name="neighbours",
                                                       wear_coefficient=wear,
                                                       partner_wear_coefficient=wear))
        model = sector.model
    return sector, model


def sector_model_3d(n_sectors: int = 6, force: float = 3e4):
    """``(sector, model)``: a coarse 3D annular sector (3 x 3 x 2 hexahedra, 20 mm wide) about
    z, hub clamped, the tip facets off the cyclic boundaries against a rigid casing, a
    static radial press and a harmonic tangential and axial force near the tip (large enough
    for every tip node to separate or slip twice per period, where the periodic state is
    unique)."""
    from fretwear.model.mesh import box

    alpha = 2 * np.pi / n_sectors
    nr, nt, nz = 3, 3, 2
    m = box(R_OUT - R_IN, alpha, 0.02, nr, nt, nz, origin=(R_IN, 0.0, 0.0))
    r, t, z = m.points.T
    pts = np.column_stack([r * np.cos(t), r * np.sin(t), z])
    side = (t < 1e-12) | (t > alpha - 1e-12)
    tip = m.boundaries["xmax"]
    tip = tip[~np.any(side[tip], axis=1)]
    load = np.flatnonzero((np.abs(r - (R_IN + (nr - 1) * (R_OUT - R_IN) / nr)) < 1e-12)
                          & ~side & (z < 1e-12))[:1]
    mesh = Mesh(pts, m.cells, "hexahedron", {"tip": tip, "hub": m.boundaries["xmin"]},
                {"left": m.node_sets["ymin"], "right": m.node_sets["ymax"],
                 "hub": m.node_sets["xmin"], "load": load})
    x = pts[load[0]]
    e_r = np.array([x[0], x[1], 0.0]) / np.hypot(x[0], x[1])
    e_t = np.array([-e_r[1], e_r[0], 0.0])
    loads = [NodalForce("load", tuple(2e4 * e_r), "constant", name="press"),
             NodalForce("load", tuple(force * e_t + force / 3 * np.array([0, 0, 1.0])), "cos",
                        name="excitation")]
    model = from_mesh(mesh, Material(2e11, 0.3, 7800.0), supports=[("hub", "all")],
                      loads=loads, contact=ContactSpec("tip", mu=0.3, name="casing"),
                      damping=Damping(loss_factor=0.01), observed={"load": "load"},
                      name="3D sector")
    return cyclic_sector(model, n_sectors, "left", "right"), model


def write_sector_case(folder, n_sectors: int = 8, engine_order: int = 3, *, slit: bool = False,
                      analysis: str = "", cyclic: str = "") -> tuple:
    """``(path, mesh_path)``: the sector of :func:`sector_model` as a case file
    (``sector.toml``) and a Gmsh 2.2 mesh file (``sector.msh``) in ``folder``: the same
    nodes (in the same order), material, hub, loads, contacts and observed point. The cyclic
    boundaries are the mesh's ``left`` and ``right`` edges (below r = 0.14 m with ``slit``,
    where ``[[contact]] neighbours`` pairs ``slit_a`` with the next sector's ``slit_b``).
    ``analysis``: the ``[analysis]`` table; ``cyclic``: extra lines of ``[cyclic]``."""
    import meshio

    from fretwear.model.mesh import rectangle as rect

    nr, nt = (4 if slit else 3), 4
    mesh = annulus_sector(n_sectors, nr=nr, slit=0.14 if slit else None)
    r = rect(R_OUT - R_IN, 2 * np.pi / n_sectors, nr, nt, origin=(R_IN, 0.0))
    bounds = dict(mesh.boundaries)
    for side, name in (("bottom", "left"), ("top", "right")):
        edges = r.boundaries[side]
        bounds[name] = edges[np.all(r.points[edges, 0] < 0.14, axis=1)] if slit else edges
    pts = np.column_stack([mesh.points, np.zeros(len(mesh.points))])
    cells, phys, field = [("quad", mesh.cells)], [np.ones(len(mesh.cells), int)], {}
    field["body"] = np.array([1, 2])
    for k, (name, facets) in enumerate(bounds.items()):
        cells.append(("line", np.asarray(facets)))
        phys.append(np.full(len(facets), 10 + k))
        field[name] = np.array([10 + k, 1])
    load = mesh.node_sets["load"]
    cells.append(("vertex", load[:, None]))
    phys.append(np.full(len(load), 100))
    field["load"] = np.array([100, 0])
    mesh_path = folder / "sector.msh"
    meshio.write(mesh_path, meshio.Mesh(pts, cells, cell_data={"gmsh:physical": phys,
                                                               "gmsh:geometrical": phys},
                                        field_data=field), file_format="gmsh22", binary=False)
    mid = mesh.points[load[0]]
    e_r = mid / np.linalg.norm(mid)
    e_t = np.array([-e_r[1], e_r[0]])
    press, force = [float(v) for v in 2e4 * e_r], [float(v) for v in 5e3 * e_t]
    neighbours = ('[[contact]]\nboundary = "slit_a"\npartner = "slit_b"\nmu = 0.3\n'
                  'gap = -2e-7\nname = "neighbours"\n') if slit else ""
    text = f"""title = "annulus sector"
[model]
type = "mesh"
file = "sector.msh"
thickness = 0.01
[material]
E = 2e11
nu = 0.3
rho = 7800.0
[damping]
loss_factor = 0.01
rayleigh_mass = 5.0
[[fixed]]
at = "hub"
[[loads]]
at = "load"
force = [{press[0]!r}, {press[1]!r}]
waveform = "constant"
name = "press"
[[loads]]
at = "load"
force = [{force[0]!r}, {force[1]!r}]
waveform = "cos"
name = "excitation"
[[contact]]
boundary = "tip"
mu = 0.3
name = "casing"
{neighbours}[observed]
tip = "load"
[cyclic]
sectors = {n_sectors}
engine_order = {engine_order}
left = "left"
right = "right"
{'neighbour = "neighbours"' if slit else ""}
{cyclic}
{analysis}
[output]
vtu = false
figures = false
"""
    path = folder / "sector.toml"
    path.write_text(text)
    return path, mesh_path
