"""Part of a face: the facets of a named boundary that lie inside a coordinate box.

A *region* restricts a boundary (contact, tractions) or a set of nodes (springs, nodal
forces, fixed DOFs) to a box given by coordinate ranges, ``{"x": (x0, x1)}`` or several
axes ``{"x": (x0, x1), "z": (z0, z1)}``; an axis not named is unbounded. A facet belongs to
the region when all its nodes do; a node belongs to it when each of its named coordinates
lies in its range, within ``1e-9`` times the model size (so a range that ends on a mesh line
keeps the nodes on it). This is how the overlap of a lap joint is selected: the whole bottom
face of the upper body does not touch the lower body, only the part above it.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from fretwear.errors import InputError
from fretwear.model.core import Mesh
from fretwear.model.mesh import model_size

AXES = "xyz"


def check_region(region, dim: int, what: str = "region") -> dict[int, tuple[float, float]]:
    """``{axis index: (lo, hi)}`` of a region ``{"x": (lo, hi), ...}`` [m].

    Raises InputError naming the region when an axis is not one of the model's, a range is
    not two finite or infinite numbers with ``lo <= hi``, or no axis is given.
    """
    if not isinstance(region, dict) or not region:
        raise InputError(f"{what} = {region!r}; expected a table of coordinate ranges such as "
                         f"{{x = [0.0, 0.01]}} (axes {list(AXES[:dim])}) [m]")
    out = {}
    for key, rng in region.items():
        axis = str(key).strip().lower()
        if axis not in AXES[:dim]:
            raise InputError(f"{what}: axis {key!r}; expected one of {list(AXES[:dim])} for a "
                             f"{dim}D model")
        try:
            lo, hi = (float(v) for v in rng)
            ok = not (math.isnan(lo) or math.isnan(hi)) and lo <= hi
        except (TypeError, ValueError):
            ok = False
        if not ok:
            raise InputError(f"{what}.{axis} = {rng!r}; expected a range [lo, hi] of two "
                             "numbers with lo <= hi [m]")
        out[AXES.index(axis)] = (lo, hi)
    return out


def inside(mesh: Mesh, nodes: np.ndarray, region, what: str = "region") -> np.ndarray:
    """(n,) bool: which of ``nodes`` lie in ``region`` (module docstring)."""
    ranges = check_region(region, mesh.dim, what)
    tol = 1e-9 * model_size(mesh)
    p = mesh.points[np.asarray(nodes, dtype=np.int64)]
    keep = np.ones(p.shape[0], dtype=bool)
    for axis, (lo, hi) in ranges.items():
        keep &= (p[:, axis] >= lo - tol) & (p[:, axis] <= hi + tol)
    return keep


def region_nodes(mesh: Mesh, nodes: np.ndarray, region, what: str) -> np.ndarray:
    """The nodes of ``nodes`` in ``region``; InputError when none is."""
    nodes = np.asarray(nodes, dtype=np.int64)
    out = nodes[inside(mesh, nodes, region, f"{what}: region")]
    if out.size == 0:
        raise InputError(f"{what}: region {region!r} holds none of its {nodes.size} nodes "
                         f"(they span {_span(mesh, nodes)})")
    return out


def restricted(mesh: Mesh, boundary: str, region, what: str) -> tuple[Mesh, str]:
    """A copy of ``mesh`` (sharing its arrays) with one more boundary: the facets of
    ``boundary`` inside ``region``; returns it and the new boundary's name
    ``"<boundary>[region]"``.

    Raises InputError when no facet of the boundary lies in the region, giving the span of
    the boundary's nodes.
    """
    if boundary not in mesh.boundaries:
        raise InputError(f"{what}: unknown boundary {boundary!r}; the mesh has boundaries "
                         f"{sorted(mesh.boundaries)}")
    facets = np.asarray(mesh.boundaries[boundary], dtype=np.int64)
    flat = facets.reshape(-1)
    keep = inside(mesh, flat, region, f"{what}: region").reshape(facets.shape).all(axis=1)
    if not keep.any():
        raise InputError(f"{what}: region {region!r} holds no facet of boundary {boundary!r} "
                         f"(a facet counts when all its nodes lie in the region; the boundary "
                         f"spans {_span(mesh, np.unique(flat))})")
    name = f"{boundary}[region]"
    return dataclasses.replace(mesh, boundaries={**mesh.boundaries, name: facets[keep]}), name


def _span(mesh: Mesh, nodes: np.ndarray) -> str:
    """``x in [a, b], y in [c, d]`` of a set of nodes."""
    p = mesh.points[np.asarray(nodes, dtype=np.int64)]
    return ", ".join(f"{AXES[k]} in [{p[:, k].min():.6g}, {p[:, k].max():.6g}]"
                     for k in range(mesh.dim))


def bounding_region(mesh: Mesh, nodes: np.ndarray) -> str:
    """The case-file text of the region spanned by ``nodes``, e.g. ``{x = [0, 0.01]}``
    (the axes along which they spread)."""
    p = mesh.points[np.asarray(nodes, dtype=np.int64)]
    size = model_size(mesh)
    parts = [f"{AXES[k]} = [{p[:, k].min():.6g}, {p[:, k].max():.6g}]"
             for k in range(mesh.dim) if np.ptp(p[:, k]) > 1e-9 * size]
    return "{" + ", ".join(parts) + "}"
