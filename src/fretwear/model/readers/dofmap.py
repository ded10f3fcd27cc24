"""The DOF map of matrices exported by an FE code: the node id and component of every row.

FE codes number a matrix's rows by (node id, component): Nastran's grid and component 1-6
(0 for a scalar point, e.g. a modal coordinate of a superelement), Abaqus's node and degree of
freedom 1-6, ANSYS's node and UX, UY, UZ, ROTX, ROTY, ROTZ. :class:`DofMap` holds that map and
turns node ids into row numbers, with one :class:`~fretwear.errors.InputError` naming the node
when it is not in the matrices. :class:`FEMatrices` is what every reader returns.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from fretwear.errors import InputError

#: ANSYS DOF labels and their component numbers (translations 1-3, rotations 4-6)
ANSYS_LABELS = {"UX": 1, "UY": 2, "UZ": 3, "ROTX": 4, "ROTY": 5, "ROTZ": 6}


@dataclass(frozen=True)
class DofMap:
    """Node id and component of each row of the matrices.

    Attributes
    ----------
    node : (n,) int
        The FE code's node (grid) id of each row.
    component : (n,) int
        Its component: 1, 2, 3 the translations along x, y, z; 4, 5, 6 the rotations; 0 a
        scalar point (e.g. a modal coordinate of a Craig-Bampton superelement).
    """

    node: np.ndarray
    component: np.ndarray

    def __post_init__(self):
        node = np.asarray(self.node).reshape(-1)
        comp = np.asarray(self.component).reshape(-1)
        for what, a in (("node", node), ("component", comp)):
            if a.size and not (np.issubdtype(a.dtype, np.number) and np.all(a == np.round(a))):
                raise InputError(f"DOF map: {what} ids must be integers, got {a[:3]!r}...")
        if node.shape != comp.shape:
            raise InputError(f"DOF map: {node.size} node ids but {comp.size} components; "
                             "expected one (node, component) per row")
        object.__setattr__(self, "node", node.astype(np.int64))
        object.__setattr__(self, "component", comp.astype(np.int64))
        key = self.node * 8 + self.component
        values, counts = np.unique(key, return_counts=True)
        if np.any(counts > 1):
            k = int(values[counts > 1][0])
            raise InputError(f"DOF map: node {k // 8} component {k % 8} is listed more than "
                             "once; expected one row per (node, component)")
        if np.any((self.component < 0) | (self.component > 6)):
            bad = int(self.component[(self.component < 0) | (self.component > 6)][0])
            raise InputError(f"DOF map: component {bad}; expected 0 (scalar point) to 6")

    @property
    def size(self) -> int:
        return int(self.node.size)

    def nodes(self) -> np.ndarray:
        """The node ids, sorted, each once."""
        return np.unique(self.node)

    def rows(self, nodes, components, what: str = "nodes") -> np.ndarray:
        """The rows ``(len(nodes), len(components))`` of the given nodes' components.

        Raises
        ------
        InputError
            A node id that is not in the matrices, or a node without one of the components.
        """
        nodes = np.asarray(nodes).reshape(-1)
        if nodes.size and not (np.issubdtype(nodes.dtype, np.number)
                               and np.all(nodes == np.round(nodes))):
            raise InputError(f"{what} = {nodes[:4].tolist()!r}...; expected integer node ids")
        nodes = nodes.astype(np.int64)
        pairs = zip(self.node.tolist(), self.component.tolist(), strict=True)
        lookup = {(n, c): i for i, (n, c) in enumerate(pairs)}
        known = set(self.node.tolist())
        out = np.empty((nodes.size, len(components)), dtype=np.int64)
        for i, n in enumerate(nodes.tolist()):
            if n not in known:
                ids = self.nodes()
                raise InputError(f"{what}: node {n} is not in the matrices' DOF map (its "
                                 f"{ids.size} nodes have ids {ids[0]}..{ids[-1]}); expected "
                                 "node ids of the exported model")
            for j, c in enumerate(components):
                row = lookup.get((n, int(c)))
                if row is None:
                    have = sorted(int(cc) for nn, cc in lookup if nn == n)
                    raise InputError(f"{what}: node {n} has no component {int(c)} in the "
                                     f"matrices (it has {have}); expected the translations "
                                     f"{list(components)}")
                out[i, j] = row
        return out

    def permuted(self, order: np.ndarray) -> DofMap:
        """The map of the rows ``order`` (a permutation or a subset)."""
        return DofMap(self.node[order], self.component[order])


@dataclass
class FEMatrices:
    """Matrices exported by an FE code, on the rows of ``dofs``.

    Attributes
    ----------
    K, M : (n, n) sparse stiffness [N/m] and mass [kg].
    dofs : the node id and component of each row.
    C : viscous damping [N s/m], or None. D : hysteretic (structural) damping [N/m], or None.
    source : the file(s) read, for messages.
    """

    K: sp.csr_matrix
    M: sp.csr_matrix
    dofs: DofMap
    C: sp.csr_matrix | None = None
    D: sp.csr_matrix | None = None
    source: str = ""

    def __post_init__(self):
        n = self.dofs.size
        for what in ("K", "M", "C", "D"):
            A = getattr(self, what)
            if A is not None and A.shape != (n, n):
                raise InputError(f"{self.source or 'matrices'}: {what} has shape {A.shape} but "
                                 f"the DOF map has {n} rows; expected ({n}, {n}) (a wrong DOF "
                                 "map?)")


def read_dofmap(path) -> DofMap:
    """A DOF map from a text file: one row of the matrices per line, ``node component``
    (two integers; ``#`` comments), or ANSYS's ``HBMAT`` mapping file (``eqn node label``
    lines under a ``Matrix Eqn  Node  DOF`` header, labels UX, UY, ...).

    Raises
    ------
    InputError
        A missing file, or a line that is neither form.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"DOF map file {str(path)!r} does not exist")
    nodes, comps = [], []
    for k, line in enumerate(path.read_text(errors="replace").splitlines(), start=1):
        text = line.split("#")[0].strip()
        if not text or text.lower().startswith("matrix"):
            continue
        tok = text.replace(",", " ").split()
        try:
            if len(tok) == 3 and tok[2].upper() in ANSYS_LABELS:
                nodes.append(int(tok[1]))
                comps.append(ANSYS_LABELS[tok[2].upper()])
            elif len(tok) == 2:
                nodes.append(int(tok[0]))
                comps.append(int(tok[1]))
            else:
                raise ValueError
        except ValueError:
            raise InputError(f"DOF map file {str(path)!r}, line {k}: {line.strip()!r}; "
                             "expected 'node component' (two integers) or ANSYS's "
                             "'eqn node UX'") from None
    return DofMap(np.array(nodes, dtype=np.int64), np.array(comps, dtype=np.int64))


def write_dofmap(path, dofs: DofMap) -> None:
    """Write ``dofs`` as a text file that :func:`read_dofmap` reads."""
    lines = ["# node component (one line per row of the matrices)"]
    lines += [f"{n} {c}" for n, c in zip(dofs.node.tolist(), dofs.component.tolist(), strict=True)]
    Path(path).write_text("\n".join(lines) + "\n")
