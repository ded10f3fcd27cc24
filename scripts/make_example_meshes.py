"""Make the Gmsh meshes of the shipped two-body examples (a developer's tool).

    pip install gmsh
    python scripts/make_example_meshes.py          # writes src/fretwear/examples/*.msh

The .msh files are shipped with the package, so users need no Gmsh. Each mesh holds two
bodies meshed conformally on their contact faces (Gmsh ``fragment``); the nodes of those
faces are then doubled, one copy per body, so that the two bodies share no node and a
node-to-node interface pairs the copies (``[[contact]] partner``). Named groups (Gmsh
physical groups): the contact faces of each body, the faces that carry loads or supports,
and one group of cells per body (a node set for its material).

* ``dovetail.msh``: a 3D dovetail blade root in a disc slot (tetrahedra): two flanks at 45
  degrees, a 1 mm clearance under the root, a 3 mm thick, 40 mm long blade (its first
  bending mode near 1.4 kHz). Groups ``blade``, ``disc``, ``blade.flank_left``,
  ``blade.flank_right``, ``disc.flank_left``, ``disc.flank_right``, ``blade.tip``,
  ``blade.front`` (the root's face z = 0), ``disc.bottom``.
* ``platform-damper.msh``: a 2D wedge damper under two blade platforms (triangles): the
  damper's two inclined faces (45 degrees) against the platforms' inclined undersides.
  Groups ``damper``, ``left``, ``right``, ``damper.left``, ``damper.right``,
  ``left.seat``, ``right.seat``, ``left.root``, ``right.root``, ``damper.bottom``,
  ``left.top``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import gmsh
import meshio
import numpy as np

OUT = Path(__file__).resolve().parents[1] / "src" / "fretwear" / "examples"


def _mesh_of(tags, dim):
    """Node coordinates (by gmsh tag) and the cells (gmsh node tags) of the given entities."""
    cells = []
    for tag in tags:
        types, _, nodes = gmsh.model.mesh.getElements(dim, tag)
        for t, n in zip(types, nodes, strict=True):
            k = gmsh.model.mesh.getElementProperties(t)[3]
            cells.append(np.asarray(n, dtype=np.int64).reshape(-1, k))
    return np.vstack(cells)


def _facets(surface_tags, dim):
    return _mesh_of(surface_tags, dim - 1)


def _split_and_write(path: Path, dim: int, bodies: dict, groups: dict):
    """Double the nodes shared by two bodies (one copy per body) and write Gmsh 2.2.

    ``bodies``: name -> entity tags of dimension ``dim``; ``groups``: name -> (body, entity
    tags of dimension ``dim - 1``): facets written with that body's copies of their nodes.
    """
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    xyz = np.asarray(xyz).reshape(-1, 3)
    index = {int(t): i for i, t in enumerate(tags)}
    body_cells = {b: np.vectorize(index.get)(_mesh_of(t, dim)) for b, t in bodies.items()}
    names = list(bodies)
    shared = np.intersect1d(np.unique(body_cells[names[0]]), np.unique(body_cells[names[1]]))
    # the second body gets copies of the shared nodes
    copy = np.arange(xyz.shape[0])
    copy[shared] = xyz.shape[0] + np.arange(shared.size)
    points = np.vstack([xyz, xyz[shared]])
    body_cells[names[1]] = copy[body_cells[names[1]]]
    cell_type = {3: "tetra", 2: "triangle"}[dim]
    facet_type = {3: "triangle", 2: "line"}[dim]
    blocks, phys, field = [], [], {}
    for k, (name, cells) in enumerate(body_cells.items()):
        blocks.append((cell_type, cells))
        phys.append(np.full(len(cells), k + 1))
        field[name] = np.array([k + 1, dim])
    for k, (name, (body, ents)) in enumerate(groups.items()):
        f = np.vectorize(index.get)(_facets(ents, dim))
        if body == names[1]:
            f = copy[f]
        blocks.append((facet_type, f))
        phys.append(np.full(len(f), 100 + k))
        field[name] = np.array([100 + k, dim - 1])
    used = np.unique(np.concatenate([c.ravel() for _, c in blocks]))
    new = np.full(points.shape[0], -1)
    new[used] = np.arange(used.size)
    blocks = [(t, new[c]) for t, c in blocks]
    mesh = meshio.Mesh(points[used], blocks,
                       cell_data={"gmsh:physical": phys, "gmsh:geometrical": phys},
                       field_data=field)
    meshio.write(path, mesh, file_format="gmsh22", binary=False)
    print(f"{path.name}: {used.size} nodes, "
          + ", ".join(f"{n} {len(c)} cells" for n, c in body_cells.items())
          + f", {shared.size} nodes doubled on the contact faces")


def _near(dim, box, eps=1e-5):
    x0, y0, z0, x1, y1, z1 = box
    return [t for _, t in gmsh.model.getEntitiesInBoundingBox(
        x0 - eps, y0 - eps, z0 - eps, x1 + eps, y1 + eps, z1 + eps, dim)]


def dovetail(size=2.0e-3, path=OUT / "dovetail.msh"):
    """The 3D dovetail (see module docstring); ``size`` the element size [m]."""
    wb, wt, h = 0.020, 0.008, 0.006  # root bottom and neck widths, flank height
    neck, a, length = 0.004, 0.003, 0.040  # neck height, blade thickness and length
    t = 0.010  # axial thickness
    W, D, gb = 0.040, 0.015, 0.001  # disc width and depth below the root, clearance
    occ = gmsh.model.occ
    top = h + neck + length

    def polygon(pts):
        p = [occ.addPoint(x, y, 0.0) for x, y in pts]
        lines = [occ.addLine(p[i], p[(i + 1) % len(p)]) for i in range(len(p))]
        return occ.addPlaneSurface([occ.addCurveLoop(lines)])

    blade = polygon([(-wb / 2, 0.0), (wb / 2, 0.0), (wt / 2, h), (wt / 2, h + neck),
                     (a / 2, h + neck), (a / 2, top), (-a / 2, top), (-a / 2, h + neck),
                     (-wt / 2, h + neck), (-wt / 2, h)])
    disc = polygon([(-W / 2, -D), (W / 2, -D), (W / 2, h), (wt / 2, h), (wb / 2, 0.0),
                    (wb / 2, -gb), (-wb / 2, -gb), (-wb / 2, 0.0), (-wt / 2, h),
                    (-W / 2, h)])
    vb = occ.extrude([(2, blade)], 0, 0, t)
    vd = occ.extrude([(2, disc)], 0, 0, t)
    vblade = [e[1] for e in vb if e[0] == 3]
    vdisc = [e[1] for e in vd if e[0] == 3]
    out, _ = occ.fragment([(3, v) for v in vblade], [(3, v) for v in vdisc])
    occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.5 * size)
    gmsh.model.mesh.generate(3)
    vols = [t_ for d_, t_ in out if d_ == 3]
    # which volume is the blade: the one reaching the tip
    def reaches_tip(v):
        return gmsh.model.getBoundingBox(3, v)[4] > top - 1e-6
    bl = [v for v in vols if reaches_tip(v)]
    di = [v for v in vols if not reaches_tip(v)]
    flank_l = _near(2, (-wb / 2, 0.0, 0.0, -wt / 2, h, t))
    flank_r = _near(2, (wt / 2, 0.0, 0.0, wb / 2, h, t))
    groups = {
        "blade.flank_left": ("blade", flank_l), "blade.flank_right": ("blade", flank_r),
        "disc.flank_left": ("disc", flank_l), "disc.flank_right": ("disc", flank_r),
        "blade.tip": ("blade", _near(2, (-a / 2, top, 0.0, a / 2, top, t))),
        "blade.front": ("blade", _near(2, (-wb / 2, 0.0, 0.0, wb / 2, top, 0.0))),
        "disc.bottom": ("disc", _near(2, (-W / 2, -D, 0.0, W / 2, -D, t))),
    }
    groups["blade.front"] = ("blade", [s for s in groups["blade.front"][1]
                                       if _owner(s) in bl])
    _split_and_write(path, 3, {"blade": bl, "disc": di}, groups)


def _owner(surface):
    up, _ = gmsh.model.getAdjacencies(2, surface)
    return int(up[0]) if len(up) else -1


def platform_damper(size=0.5e-3, path=OUT / "platform-damper.msh"):
    """The 2D under-platform damper (see module docstring)."""
    occ = gmsh.model.occ
    B, b, hd = 0.004, 0.001, 0.003  # damper half widths (bottom, top), height: 45 degrees
    L, tp = 0.012, 0.003  # platforms reach x = +-L; their thickness above the damper top

    def polygon(pts):
        p = [occ.addPoint(x, y, 0.0) for x, y in pts]
        lines = [occ.addLine(p[i], p[(i + 1) % len(p)]) for i in range(len(p))]
        return occ.addPlaneSurface([occ.addCurveLoop(lines)])

    damper = polygon([(-B, -hd), (B, -hd), (b, 0.0), (-b, 0.0)])
    right = polygon([(b, 0.0), (B, -hd), (L, -hd), (L, tp), (b, tp)])
    left = polygon([(-b, 0.0), (-b, tp), (-L, tp), (-L, -hd), (-B, -hd)])
    occ.fragment([(2, damper)], [(2, right), (2, left)])
    occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.model.mesh.generate(2)
    faces = {side: [t_ for t_ in _near(1, (min(sg * b, sg * B), -hd, 0.0,
                                           max(sg * b, sg * B), 0.0, 0.0))
                    if _is_inclined(t_)]
             for side, sg in (("left", -1.0), ("right", 1.0))}
    surfaces = [t_ for _, t_ in gmsh.model.getEntities(2)]

    def centre_x(srf):
        bb = gmsh.model.getBoundingBox(2, srf)
        return 0.5 * (bb[0] + bb[3])

    groups = {
        "damper.left": ("damper", faces["left"]), "damper.right": ("damper", faces["right"]),
        "left.seat": ("left", faces["left"]), "right.seat": ("right", faces["right"]),
        "left.root": ("left", _near(1, (-L, -hd, 0.0, -L, tp, 0.0))),
        "right.root": ("right", _near(1, (L, -hd, 0.0, L, tp, 0.0))),
        "damper.bottom": ("damper", _near(1, (-B, -hd, 0.0, B, -hd, 0.0))),
        "left.top": ("left", _near(1, (-L, tp, 0.0, -b, tp, 0.0))),
    }
    bodies = {"damper": [srf for srf in surfaces if abs(centre_x(srf)) < 1e-6],
              "left": [srf for srf in surfaces if centre_x(srf) < -1e-6],
              "right": [srf for srf in surfaces if centre_x(srf) > 1e-6]}
    _split_three(path, bodies, groups)


def _is_inclined(curve):
    b = gmsh.model.getBoundingBox(1, curve)
    return abs(b[3] - b[0]) > 1e-9 and abs(b[4] - b[1]) > 1e-9


def _split_three(path, bodies, groups):
    """As :func:`_split_and_write` for three bodies: every body after the first gets its own
    copies of the nodes it shares with the bodies before it."""
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    xyz = np.asarray(xyz).reshape(-1, 3)
    index = {int(t): i for i, t in enumerate(tags)}
    cells = {b: np.vectorize(index.get)(_mesh_of(t, 2)) for b, t in bodies.items()}
    points = [xyz]
    n = xyz.shape[0]
    maps = {}
    seen = set()
    for b, c in cells.items():
        mine = np.unique(c)
        clash = np.array(sorted(seen & set(mine.tolist())), dtype=np.int64)
        m = np.arange(n)
        if clash.size:
            m[clash] = sum(p.shape[0] for p in points) + np.arange(clash.size)
            points.append(xyz[clash])
        maps[b] = m
        cells[b] = m[c]
        seen |= set(mine.tolist())
    pts = np.vstack(points)
    blocks, phys, field = [], [], {}
    for k, (b, c) in enumerate(cells.items()):
        blocks.append(("triangle", c))
        phys.append(np.full(len(c), k + 1))
        field[b] = np.array([k + 1, 2])
    for k, (name, (b, ents)) in enumerate(groups.items()):
        f = maps[b][np.vectorize(index.get)(_mesh_of(ents, 1))]
        blocks.append(("line", f))
        phys.append(np.full(len(f), 100 + k))
        field[name] = np.array([100 + k, 1])
    mesh = meshio.Mesh(pts, blocks, cell_data={"gmsh:physical": phys,
                                               "gmsh:geometrical": phys}, field_data=field)
    meshio.write(path, mesh, file_format="gmsh22", binary=False)
    print(f"{path.name}: {pts.shape[0]} nodes, "
          + ", ".join(f"{b} {len(c)} cells" for b, c in cells.items()))


def main(argv):
    which = argv[1:] or ["dovetail", "platform-damper"]
    for name in which:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add(name)
        {"dovetail": dovetail, "platform-damper": platform_damper}[name]()
        gmsh.finalize()


if __name__ == "__main__":
    main(sys.argv)
