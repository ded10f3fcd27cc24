"""Make the Gmsh mesh of the shipped 3D bladed-disk sector (a developer's tool).

    pip install gmsh
    python scripts/make_bladed_disk_mesh.py        # writes src/fretwear/examples/bladed-disk.msh

One sector (N = 24, 15 degrees, axis z through the origin) of a bladed disk, every part an
extrusion along the axis (10 mm) of a profile in the plane of the disk: the disk sector
(hub radius 60 mm, rim 100 mm) with a dovetail slot; the blade (a dovetail root in the slot,
a neck, a platform, an airfoil plate 3 mm thick reaching r = 148 mm); an under-platform
damper (a wedge centred on the sector's edge theta = 15 degrees) under the gap between this
blade's platform and the next blade's. The disk's faces theta = 0 and theta = 15 degrees are
meshed alike under the rotation (Gmsh ``setPeriodic``), and so are the damper's right face
and the platform's left seat: the damper touches this blade's right seat and the next
blade's left seat (a ``[cyclic] neighbour`` contact). The nodes shared by two bodies (the
root flanks against the slot flanks, the damper against the right seat) are doubled, one copy
per body, as in scripts/make_example_meshes.py. Groups: ``disk``, ``blade``, ``damper``,
``disk.left``, ``disk.right`` (the cyclic faces), ``disk.hub``, ``disk.flank_left``,
``disk.flank_right``, ``blade.flank_left``, ``blade.flank_right``, ``blade.seat_left``,
``blade.seat_right``, ``blade.tip``, ``damper.left``, ``damper.right``, ``damper.bottom``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import gmsh
import meshio
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from make_example_meshes import OUT, _mesh_of  # noqa: E402

N = 24
ALPHA = 2 * np.pi / N
T = 0.010  # axial thickness [m]
R_HUB, R_RIM = 0.060, 0.100
WB, WT, H, GB = 0.012, 0.006, 0.006, 0.001  # root bottom and neck widths, flank height, gap
NECK, WP, TP, C = 0.006, 0.022, 0.003, 0.002  # neck height, platform width and thickness,
A, L = 0.003, 0.040  # airfoil thickness and length                         seat chamfer
HD = 0.003  # damper depth below its seats


def _frame(theta):
    """Local (u tangential, v radial) -> global (x, y) at angle theta."""
    ev = np.array([np.cos(theta), np.sin(theta)])
    eu = np.array([-np.sin(theta), np.cos(theta)])
    return lambda u, v: u * eu + v * ev


def _polygon(pts):
    occ = gmsh.model.occ
    p = [occ.addPoint(x, y, 0.0) for x, y in pts]
    lines = [occ.addLine(p[i], p[(i + 1) % len(p)]) for i in range(len(p))]
    return occ.addPlaneSurface([occ.addCurveLoop(lines)])


def profiles():
    """The three profiles (lists of (x, y) points) and the seat chamfers' end points."""
    g = _frame(ALPHA / 2)
    v_top = R_RIM * np.cos(ALPHA / 2)  # the rim chord
    v0 = v_top - H
    vp = v_top + NECK
    disk = [(R_HUB, 0.0), tuple(R_HUB * np.array([np.cos(ALPHA), np.sin(ALPHA)])),
            tuple(R_RIM * np.array([np.cos(ALPHA), np.sin(ALPHA)])),
            tuple(g(WT / 2, v_top)), tuple(g(WB / 2, v0)), tuple(g(WB / 2, v0 - GB)),
            tuple(g(-WB / 2, v0 - GB)), tuple(g(-WB / 2, v0)), tuple(g(-WT / 2, v_top)),
            (R_RIM, 0.0)]
    half = [(WB / 2, v0), (WT / 2, v_top), (WT / 2, vp), (WP / 2 - C, vp), (WP / 2, vp + C),
            (WP / 2, vp + TP), (A / 2, vp + TP), (A / 2, vp + TP + L)]
    blade = [g(u, v) for u, v in half] + [g(-u, v) for u, v in reversed(half)]
    pa, pb = g(WP / 2 - C, vp), g(WP / 2, vp + C)  # this platform's right seat
    d = _frame(ALPHA)
    to_d = np.array([[-np.sin(ALPHA), np.cos(ALPHA)], [np.cos(ALPHA), np.sin(ALPHA)]])
    ua, va = to_d @ pa
    ub, vb = to_d @ pb
    damper = [d(ua, va - HD), d(ua, va), d(ub, vb), d(-ub, vb), d(-ua, va), d(-ua, va - HD)]
    return disk, [tuple(p) for p in blade], [tuple(p) for p in damper], (pa, pb)


def _rotation(theta):
    c, s = np.cos(theta), np.sin(theta)
    return [c, -s, 0, 0, s, c, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]


def _surface_near(points, tol=1e-6):
    """The surface (dim 2) whose bounding box holds all ``points`` (3D) and is smallest."""
    best, size = None, np.inf
    for _, s in gmsh.model.getEntities(2):
        b = np.array(gmsh.model.getBoundingBox(2, s))
        if all(np.all(p >= b[:3] - tol) and np.all(p <= b[3:] + tol) for p in points):
            vol = np.prod(b[3:] - b[:3] + 1e-9)
            if vol < size:
                best, size = s, vol
    return best


def _face(p, q):
    """The extruded face over the profile edge p-q (z from 0 to T)."""
    return _surface_near([np.r_[p, 0.0], np.r_[q, 0.0], np.r_[p, T], np.r_[q, T]])


def bladed_disk(size=5.0e-3, path=OUT / "bladed-disk.msh"):
    occ = gmsh.model.occ
    disk_p, blade_p, damper_p, (pa, pb) = profiles()
    vols = {}
    for name, prof in (("disk", disk_p), ("blade", blade_p), ("damper", damper_p)):
        ext = occ.extrude([(2, _polygon(prof))], 0, 0, T)
        vols[name] = [e[1] for e in ext if e[0] == 3]
    occ.fragment([(3, v) for v in vols["blade"]],
                 [(3, v) for v in vols["disk"] + vols["damper"]])
    occ.synchronize()
    g = _frame(ALPHA / 2)
    v_top = R_RIM * np.cos(ALPHA / 2)
    v0 = v_top - H
    faces = {
        "disk.left": _face(np.array([R_HUB, 0.0]), np.array([R_RIM, 0.0])),
        "disk.right": _face(R_HUB * np.array([np.cos(ALPHA), np.sin(ALPHA)]),
                            R_RIM * np.array([np.cos(ALPHA), np.sin(ALPHA)])),
        "disk.hub": _face(np.array([R_HUB, 0.0]),
                          R_HUB * np.array([np.cos(ALPHA), np.sin(ALPHA)])),
        "flank_left": _face(g(-WB / 2, v0), g(-WT / 2, v_top)),
        "flank_right": _face(g(WB / 2, v0), g(WT / 2, v_top)),
        "seat_right": _face(pa, pb),
        "seat_left": _face(g(-(WP / 2 - C), v_top + NECK), g(-WP / 2, v_top + NECK + C)),
    }
    d = _frame(ALPHA)
    to_d = np.array([[-np.sin(ALPHA), np.cos(ALPHA)], [np.cos(ALPHA), np.sin(ALPHA)]])
    ua, va = to_d @ pa
    ub, vb = to_d @ pb
    faces["damper.right"] = _face(d(-ua, va), d(-ub, vb))
    faces["damper.bottom"] = _face(d(ua, va - HD), d(-ua, va - HD))
    tip_v = v_top + NECK + TP + L
    faces["blade.tip"] = _face(g(-A / 2, tip_v), g(A / 2, tip_v))
    gmsh.model.mesh.setPeriodic(2, [faces["disk.right"]], [faces["disk.left"]],
                                _rotation(ALPHA))
    gmsh.model.mesh.setPeriodic(2, [faces["damper.right"]], [faces["seat_left"]],
                                _rotation(ALPHA))
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.3 * size)
    # finer on the contact faces: enough nodes for a wear map
    field = gmsh.model.mesh.field
    dist = field.add("Distance")
    field.setNumbers(dist, "SurfacesList", [faces[k] for k in ("flank_left", "flank_right",
                                                                "seat_left", "seat_right",
                                                                "damper.right")])
    thr = field.add("Threshold")
    field.setNumber(thr, "InField", dist)
    field.setNumber(thr, "SizeMin", 0.5 * size)
    field.setNumber(thr, "SizeMax", size)
    field.setNumber(thr, "DistMin", 0.5e-3)
    field.setNumber(thr, "DistMax", 4e-3)
    field.setAsBackgroundMesh(thr)
    gmsh.model.mesh.generate(3)

    def body_of(v):
        c = occ.getCenterOfMass(3, v)
        r = np.hypot(c[0], c[1])
        if abs(np.arctan2(c[1], c[0]) - ALPHA) < 0.3 * ALPHA and r < R_RIM + NECK + 1e-3 \
                and r > R_RIM:
            return "damper"
        return "disk" if r < v_top - 0.5 * H else "blade"

    bodies = {"disk": [], "blade": [], "damper": []}
    for _, v in gmsh.model.getEntities(3):
        bodies[body_of(v)].append(v)
    groups = {
        "disk.left": ("disk", [faces["disk.left"]]),
        "disk.right": ("disk", [faces["disk.right"]]),
        "disk.hub": ("disk", [faces["disk.hub"]]),
        "disk.flank_left": ("disk", [faces["flank_left"]]),
        "disk.flank_right": ("disk", [faces["flank_right"]]),
        "blade.flank_left": ("blade", [faces["flank_left"]]),
        "blade.flank_right": ("blade", [faces["flank_right"]]),
        "blade.seat_left": ("blade", [faces["seat_left"]]),
        "blade.seat_right": ("blade", [faces["seat_right"]]),
        "blade.tip": ("blade", [faces["blade.tip"]]),
        "damper.left": ("damper", [faces["seat_right"]]),
        "damper.right": ("damper", [faces["damper.right"]]),
        "damper.bottom": ("damper", [faces["damper.bottom"]]),
    }
    _split_write(path, bodies, groups)


def _split_write(path, bodies, groups):
    """Every body after the first gets its own copies of the nodes it shares with the bodies
    before it; tetrahedra per body, triangles per group; Gmsh 2.2."""
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    xyz = np.asarray(xyz).reshape(-1, 3)
    index = {int(t): i for i, t in enumerate(tags)}
    cells = {b: np.vectorize(index.get)(_mesh_of(t, 3)) for b, t in bodies.items()}
    points, n, maps, seen = [xyz], xyz.shape[0], {}, set()
    for b, c in cells.items():
        mine = np.unique(c)
        clash = np.array(sorted(seen & set(mine.tolist())), dtype=np.int64)
        m = np.arange(n)
        if clash.size:
            m[clash] = sum(p.shape[0] for p in points) + np.arange(clash.size)
            points.append(xyz[clash])
        maps[b], cells[b] = m, m[c]
        seen |= set(mine.tolist())
    pts = np.vstack(points)
    blocks, phys, field = [], [], {}
    for k, (b, c) in enumerate(cells.items()):
        blocks.append(("tetra", c))
        phys.append(np.full(len(c), k + 1))
        field[b] = np.array([k + 1, 3])
    for k, (name, (b, ents)) in enumerate(groups.items()):
        f = maps[b][np.vectorize(index.get)(_mesh_of(ents, 2))]
        blocks.append(("triangle", f))
        phys.append(np.full(len(f), 100 + k))
        field[name] = np.array([100 + k, 2])
    used = np.unique(np.concatenate([c.ravel() for _, c in blocks]))
    new = np.full(pts.shape[0], -1)
    new[used] = np.arange(used.size)
    mesh = meshio.Mesh(pts[used], [(t, new[c]) for t, c in blocks],
                       cell_data={"gmsh:physical": phys, "gmsh:geometrical": phys},
                       field_data=field)
    meshio.write(path, mesh, file_format="gmsh22", binary=False)
    print(f"{path.name}: {used.size} nodes, "
          + ", ".join(f"{b} {len(c)} tetrahedra" for b, c in cells.items()))


def main(argv):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("bladed-disk")
    bladed_disk(*(float(a) for a in argv[1:2]))
    gmsh.finalize()


if __name__ == "__main__":
    main(sys.argv)
