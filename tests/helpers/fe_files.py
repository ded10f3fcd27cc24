"""A mesh model exported as an FE code would: matrices on rows named (node id, component),
files written from the documented formats (DMIG, ASCII OP4, Abaqus .mtx) or by SciPy (Matrix
Market, Harwell-Boeing), and the contact, loads, supports and observed points named by node
ids. Node id = mesh node number + 1 (FE codes count from 1)."""

from __future__ import annotations

from pathlib import Path

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


def write_ansys_full(path, K, M, dofs: DofMap, held=()) -> None:
    """An uncompressed ANSYS ``.full`` file from its documented layout (``fdfull.inc``):
    records ``[n, flags, data, n]`` (flags bit 31: integers); the standard header (file
    number 4, version 18.0), the full header, the DOF labels, node ids, DOFs per node, the
    constraint table (``held`` rows negative, their diagonal 1 as MAPDL writes it) and one
    pair of records a column (rows from 1 of the lower triangle, values) for K and for M.
    Every node has the same components, its rows consecutive (a node-major DOF map)."""
    out: list[np.ndarray] = []
    pos = [0]

    def record(data, integer=True):
        data = np.asarray(data, "<i4" if integer else "<f8")
        words = data.view("<i4") if not integer else data
        flag = np.int32(-2**31) if integer else np.int32(0)
        out.append(np.concatenate([[words.size, flag], words, [words.size]]).astype("<i4"))
        start = pos[0]
        pos[0] += words.size + 3
        return start

    nodes, first = np.unique(dofs.node, return_index=True)
    nodes = dofs.node[np.sort(first)]
    labels = dofs.component[dofs.node == nodes[0]]
    n = dofs.size
    held = np.asarray(held, dtype=np.int64)
    K, M = (sp.lil_matrix(A) for A in (K, M))
    for A in (K, M):
        for r in held:
            A[r, :] = 0.0
            A[:, r] = 0.0
        for r in held:
            A[r, r] = 1.0 if A is K else 0.0
    K, M = (sp.tril(sp.csc_matrix(A)).tocsc() for A in (K, M))
    std = np.zeros(100, dtype=np.int64)
    std[0] = 4  # file number: a .full file
    std[9] = int.from_bytes(b"0.81", "little")  # version "18.0", stored reversed
    record(std)
    header = np.zeros(100, dtype=np.int64)
    header_at = record(header)  # filled in below
    record(labels)
    record(nodes)

    def matrix(A):
        A.sort_indices()
        at = pos[0]
        for j in range(n):
            rows = A.indices[A.indptr[j]:A.indptr[j + 1]]
            record(rows + 1)
            record(A.data[A.indptr[j]:A.indptr[j + 1]], integer=False)
        return at, A.nnz

    ptr_k, nterm_k = matrix(K)
    ptr_m, nterm_m = matrix(M)
    const = np.arange(1, n + 1)
    const[held] = -const[held]
    ptr_dof = record(np.full(nodes.size, labels.size))
    record(const)
    header[[0, 1, 2, 7, 8, 18, 26, 32, 33, 35]] = [-4, n, n - held.size, labels.size, nterm_k,
                                                   ptr_k, ptr_m, nodes.size, nterm_m, ptr_dof]
    out[1] = np.concatenate([[100, -2**31], header, [100]]).astype("<i4")
    assert header_at == 103
    Path(path).write_bytes(np.concatenate(out).tobytes())
