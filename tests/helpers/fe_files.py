"""A mesh model exported as an FE code would: matrices on rows named (node id, component),
files written from the documented formats (DMIG, ASCII OP4, Abaqus .mtx) or by SciPy (Matrix
Market, Harwell-Boeing), and the contact, loads, supports and observed points named by node
ids. Node id = mesh node number + 1 (FE codes count from 1)."""

from __future__ import annotations

import numpy as np
import scipy.io
import scipy.sparse as sp

from fretwear.model.readers import DofMap, NodeContact, NodeForce, NodeTable


def dofmap_of(model) -> DofMap:
    d = model.dim
    i = np.arange(model.ndof)
    return DofMap(i // d + 1, i % d + 1)


def node_table(model) -> NodeTable:
    pts = model.mesh.points
    xyz = np.zeros((len(pts), 3))
    xyz[:, :model.dim] = pts
    return NodeTable(np.arange(len(pts)) + 1, xyz)


def contacts_of(model) -> list[NodeContact]:
    """The model's interfaces as NodeContact records (frames, areas, gaps as they are)."""
    c, d = model.contact, model.dim
    out = []
    idx = c.interface_index()
    for k, name in enumerate(c.names()):
        sel = idx == k
        out.append(NodeContact(
            nodes=c.dofs[sel, 0] // d + 1, mu=float(c.mu_nodes()[sel][0]),
            frames=c.frame[sel], gap=c.gap[sel], area=c.area[sel],
            partners=None if c.partner_dofs is None else c.partner_dofs[sel, 0] // d + 1,
            wear_coefficient=float(c.wear_nodes()[sel][0]),
            partner_wear_coefficient=float(c.partner_wear_nodes()[sel][0]), name=name))
    return out


def fixed_of(model) -> list:
    d = model.dim
    f = np.asarray(model.fixed_dofs)
    return [(f[f % d == c] // d + 1, [c + 1]) for c in range(d) if np.any(f % d == c)]


def forces_of(model) -> list[NodeForce]:
    d = model.dim
    nn = model.ndof // d
    return [NodeForce(np.arange(nn) + 1, ld.vector.reshape(nn, d), ld.waveform, ld.name,
                      ld.coefficients) for ld in model.loads]


def observed_of(model) -> dict:
    return {p.name: int(p.dofs[0]) // model.dim + 1 for p in model.observed}


# --- writers from the documented formats ------------------------------------------------------
def _large(fields: list[str]) -> list[str]:
    """One DMIG* card: the first line with 4 fields, continuations with 4 each."""
    lines = []
    for k in range(0, len(fields), 4):
        chunk = "".join(f"{v:>16}" for v in fields[k:k + 4])
        lines.append(("DMIG*   " if k == 0 else "*       ") + chunk)
    return lines


def write_dmig(path, matrices: dict, dofs: DofMap) -> None:
    """Symmetric DMIG matrices (IFO 6, TIN 2, lower triangle) in large-field punch form."""
    lines = ["$ DMIG matrices written from the documented format (large field)"]
    for name, A in matrices.items():
        L = sp.tril(sp.csc_matrix(A)).tocsc()
        lines += _large([name, "0", "6", "2", "2", "", "", str(L.shape[1])])
        for j in range(L.shape[1]):
            rows = L.indices[L.indptr[j]:L.indptr[j + 1]]
            vals = L.data[L.indptr[j]:L.indptr[j + 1]]
            if rows.size == 0:
                continue
            fields = [name, str(dofs.node[j]), str(dofs.component[j]), ""]
            for r, v in zip(rows, vals, strict=True):
                fields += [str(dofs.node[r]), str(dofs.component[r]),
                           f"{v:.9E}".replace("E", "D"), ""]
            lines += _large(fields)
    path.write_text("\n".join(lines) + "\n")


def write_op4(path, matrices: dict, sparse: bool = False, binary: bool = False) -> None:
    """OP4 of real double-precision matrices (OUTPUT4's documented format): ASCII with 3
    values of 23 characters a line (1P,3E23.16) or binary (Fortran records, little-endian
    4-byte integers); columns dense from their first to their last nonzero row, or
    ``sparse``: strings of consecutive nonzero rows, each headed by ``IS = IROW + 65536 (L +
    1)`` (``L`` words of values: 2 a double)."""
    out = bytearray() if binary else []

    def record(ints, vals=()):
        if binary:
            body = np.asarray(ints, "<i4").tobytes() + np.asarray(vals, "<f8").tobytes()
            out.extend(np.int32(len(body)).tobytes() + body + np.int32(len(body)).tobytes())
            return
        out.append("".join(f"{i:8d}" for i in ints[:3]))
        for k in range(0, len(vals), 3):
            out.append("".join(f"{x:23.16E}" for x in vals[k:k + 3]))

    for name, A in matrices.items():
        A = sp.csc_matrix(A)
        A.sort_indices()
        n = A.shape[0]
        if binary:
            body = np.array([n, n, 6, 2], "<i4").tobytes() + f"{name:<8s}".encode()
            out.extend(np.int32(24).tobytes() + body + np.int32(24).tobytes())
        else:
            out.append(f"{n:8d}{n:8d}{6:8d}{2:8d}{name:<8s}1P,3E23.16")
        for j in range(n):
            rows = A.indices[A.indptr[j]:A.indptr[j + 1]]
            vals = A.data[A.indptr[j]:A.indptr[j + 1]]
            if rows.size == 0:
                continue
            if not sparse:
                col = np.zeros(rows[-1] - rows[0] + 1)
                col[rows - rows[0]] = vals
                record([j + 1, rows[0] + 1, 2 * col.size], col)
                continue
            brk = np.flatnonzero(np.diff(rows) != 1) + 1
            runs = list(zip(np.split(rows, brk), np.split(vals, brk), strict=True))
            nw = sum(1 + 2 * r.size for r, _ in runs)
            if binary:
                words = b"".join(np.int32(r[0] + 1 + 65536 * (2 * r.size + 1)).tobytes()
                                 + np.asarray(v, "<f8").tobytes() for r, v in runs)
                body = np.array([j + 1, 0, nw], "<i4").tobytes() + words
                out.extend(np.int32(len(body)).tobytes() + body
                           + np.int32(len(body)).tobytes())
                continue
            out.append(f"{j + 1:8d}{0:8d}{nw:8d}")
            for r, v in runs:
                out.append(f"{r[0] + 1 + 65536 * (2 * r.size + 1):8d}")
                for k in range(0, v.size, 3):
                    out.append("".join(f"{x:23.16E}" for x in v[k:k + 3]))
        record([n + 1, 1, 2], [1.0])
    if binary:
        path.write_bytes(bytes(out))
    else:
        path.write_text("\n".join(out) + "\n")


def write_abaqus_substructure(path, matrices: dict, dofs: DofMap) -> None:
    """``*USER ELEMENT`` and ``*MATRIX, TYPE=..`` blocks (lower triangle row by row, 4 a
    line); every node with the same components (those of the first node)."""
    nodes = np.unique(dofs.node)
    comps = dofs.component[dofs.node == nodes[0]]
    lines = ["**", "** GENERATION OF SUBSTRUCTURE Z1", f"*USER ELEMENT, NODES={nodes.size}, "
             "LINEAR", "** ELEMENT NODES"]
    for k in range(0, nodes.size, 10):
        lines.append("** " + ", ".join(str(n) for n in nodes[k:k + 10]))
    lines.append(", ".join(str(c) for c in comps))
    for kind, A in matrices.items():
        A = np.asarray(sp.csr_matrix(A).toarray())
        lines.append(f"*MATRIX,TYPE={kind}")
        for i in range(A.shape[0]):
            row = A[i, :i + 1]
            for k in range(0, row.size, 4):
                lines.append(", ".join(f"{x:.16E}" for x in row[k:k + 4])
                             + ("," if k + 4 < row.size else ""))
    path.write_text("\n".join(lines) + "\n")


def write_abaqus_matrix_input(path, A, dofs: DofMap) -> None:
    """``row node, row DOF, column node, column DOF, value`` lines (lower triangle)."""
    L = sp.tril(sp.coo_matrix(A)).tocoo()
    lines = [f"{dofs.node[i]},{dofs.component[i]}, {dofs.node[j]},{dofs.component[j]}, {v:.16E}"
             for i, j, v in zip(L.row, L.col, L.data, strict=True)]
    path.write_text("\n".join(lines) + "\n")


def write_matrix_market(path, A) -> None:
    scipy.io.mmwrite(str(path), sp.coo_matrix(A), precision=17)


def write_harwell_boeing(path, A) -> None:
    scipy.io.hb_write(str(path), sp.csc_matrix(A))


def write_bdf_mesh(path, model) -> None:
    """The mesh as Nastran bulk data (free field, every digit): ``GRID`` cards (node id =
    number + 1) and ``CQUAD4``/``CTRIA3``/``CTETRA``/``CHEXA`` cards of its cells."""
    pts = model.mesh.points
    xyz = np.zeros((len(pts), 3))
    xyz[:, :model.dim] = pts
    lines = [f"GRID,{i + 1},,{x!r},{y!r},{z!r}" for i, (x, y, z) in enumerate(xyz.tolist())]
    card = {3: "CTRIA3", 4: "CTETRA" if model.mesh.cell_type == "tetra" else "CQUAD4",
            8: "CHEXA"}[model.mesh.cells.shape[1]]
    for e, cell in enumerate(np.asarray(model.mesh.cells) + 1):
        ids = [str(int(n)) for n in cell]
        lines.append(",".join([card, str(e + 1), "1", *ids[:6]]))
        if len(ids) > 6:
            lines.append(",".join(["", *ids[6:]]))
    path.write_text("\n".join(lines) + "\n")
