"""The shipped dovetail (6618 DOFs, 86 pairs on two flanks) exported as an FE code would, read
back with fretwear.model.readers, against the model built from the mesh: the same modes,
periodic solve and wear step to 1e-10?

Formats: Nastran DMIG (large field, 10 significant digits) and OP4 (ASCII and binary, sparse
strings, 17 digits or the doubles themselves), Abaqus ``*MATRIX OUTPUT, FORMAT=MATRIX
INPUT`` (17 digits) and ANSYS ``.full`` (the doubles; K and M only: D given as a matrix,
or from the case's loss factor), written from the documented formats
(tests/helpers/fe_files.py); with
``--pynastran PYTHON`` (a Python whose environment has pyNastran and NumPy < 2, never a
fretwear dependency) also pyNastran's own DMIG and ASCII OP4 writers. A format that keeps 10
digits is compared with the mesh model whose K, M, D are rounded to 10 digits, as the files
hold them. ``--superelement`` adds the dovetail as a Craig-Bampton superelement with every
fixed-interface mode kept (exact; a dense eigenproblem of the 5.9e3 interior DOFs).

    python3 -m venv /tmp/pynastran-venv && /tmp/pynastran-venv/bin/pip install "numpy<2" \\
        pyNastran
    PYTHONPATH=src OPENBLAS_NUM_THREADS=1 python studies/dovetail_exports.py \\
        --pynastran /tmp/pynastran-venv/bin/python --superelement

Prints one line a model and writes docs/studies/figures/dovetail-exports.json; the write-up
is docs/studies/dovetail-exports.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import scipy.sparse as sp

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))  # the writers of the documented formats

from helpers import fe_files as ff  # noqa: E402

from fretwear import simulate_wear, solve_periodic  # noqa: E402
from fretwear.analyses.run import load_case  # noqa: E402
from fretwear.examples import example_path  # noqa: E402
from fretwear.hb.fourier import FourierBasis  # noqa: E402
from fretwear.io.case import build_model  # noqa: E402
from fretwear.linear import modes  # noqa: E402
from fretwear.model.build import Damping  # noqa: E402
from fretwear.model.readers import from_fe, read_fe, write_dofmap  # noqa: E402
from fretwear.wear import WearOptions  # noqa: E402

BASIS = FourierBasis.up_to(1, 16)
F_HZ = 1800.0
NAMES = {"K": "KAAX", "M": "MAAX", "D": "K4AX"}
LOSS_FACTOR = 0.002  # [damping] of the dovetail's case file

PYNASTRAN = '''
import sys
import numpy as np
np.in1d = getattr(np, "in1d", np.isin)
import scipy.sparse as sp
from pyNastran.bdf.bdf import BDF
from pyNastran.op4.op4 import OP4
d = sys.argv[1]
z = np.load(d + "/mats.npz")
node, comp = z["node"], z["comp"]
from pyNastran.bdf.field_writer_double import print_scientific_double
model, op4, rounded = BDF(debug=None), {}, {}
for name in ("KAAX", "MAAX", "K4AX"):
    A = sp.csc_matrix((z[name + "_data"], z[name + "_indices"], z[name + "_indptr"]),
                      shape=(node.size, node.size))
    L = sp.tril(A).tocoo()
    order = np.lexsort((L.row, L.col))
    r, c, v = L.row[order], L.col[order], L.data[order]
    model.add_dmig(name, ifo=6, tin=2, tout=2, polar=0, ncols=node.size,
                   GCj=[(int(node[j]), int(comp[j])) for j in c],
                   GCi=[(int(node[i]), int(comp[i])) for i in r], Real=list(v))
    op4[name] = (6, A.tocoo())
    rounded[name] = [float(print_scientific_double(x).replace("D", "E")) for x in A.data]
np.savez(d + "/rounded.npz", **rounded)
model.write_bdf(d + "/pynastran.bdf", size=16, is_double=True)
OP4().write_op4(d + "/pynastran.op4", op4, precision="double", is_binary=False)
print("RESULT ok")
'''


def ten_digits(A):
    """``A`` with every entry rounded to 10 significant digits, as DMIG's fields hold them."""
    A = sp.csr_matrix(A, copy=True)
    A.data = np.char.mod("%.9e", A.data).astype(float)
    return A


def rebuilt(model, fe, damping=None):
    return from_fe(fe, contact=ff.contacts_of(model), nodes=ff.node_table(model),
                   loads=ff.forces_of(model), fixed=ff.fixed_of(model),
                   observed=ff.observed_of(model), name=model.name, damping=damping)


def cpu() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_utime


def exports(m0, d: Path, pynastran: str | None) -> dict:
    """Every format's files of the dovetail's K, M, D: name -> (read_fe args, kwargs)."""
    dofs = ff.dofmap_of(m0)
    mats = {NAMES[k]: getattr(m0, k) for k in NAMES}
    write_dofmap(d / "dofs.txt", dofs)
    ff.write_dmig(d / "m.pch", mats, dofs)
    ff.write_op4(d / "ascii.op4", mats, sparse=True)
    ff.write_op4(d / "binary.op4", mats, sparse=True, binary=True)
    for k in NAMES:
        ff.write_abaqus_matrix_input(d / f"{k}.mtx", getattr(m0, k), dofs)
    ff.write_ansys_full(d / "dovetail.full", m0.K, m0.M, dofs)
    out = {"dmig": ((d / "m.pch",), {}),
           "ansys full, D given": ((d / "dovetail.full",), {}),
           "ansys full, loss factor": ((d / "dovetail.full",), {}),
           "op4 ascii": ((d / "ascii.op4",), {"dofmap": d / "dofs.txt"}),
           "op4 binary": ((d / "binary.op4",), {"dofmap": d / "dofs.txt"}),
           "abaqus matrix input": ((d / "K.mtx", d / "M.mtx"),
                                   {"D": d / "D.mtx", "format": "abaqus-matrix-input"})}
    if pynastran:
        arrays = {"node": dofs.node, "comp": dofs.component}
        for name, A in mats.items():
            A = sp.csc_matrix(A)
            arrays.update({f"{name}_data": A.data, f"{name}_indices": A.indices,
                           f"{name}_indptr": A.indptr})
        np.savez(d / "mats.npz", **arrays)
        (d / "child.py").write_text(PYNASTRAN)
        proc = subprocess.run([pynastran, str(d / "child.py"), str(d)], capture_output=True,
                              text=True, timeout=3600)
        if "RESULT ok" not in proc.stdout:
            print("pyNastran writers failed:", proc.stderr.strip().splitlines()[-1:])
        else:
            out["dmig (pyNastran)"] = ((d / "pynastran.bdf",), {})
            z = np.load(d / "rounded.npz")  # the values as pyNastran's writer rounds them
            for name, A in mats.items():
                A = sp.csc_matrix(A, copy=True)
                A.data = z[name]
                ROUNDED_BY_PYNASTRAN[name] = A
            out["op4 ascii (pyNastran)"] = ((d / "pynastran.op4",), {"dofmap": d / "dofs.txt"})
    return out


def fingerprint(model) -> str:
    """A hash of every array the answers depend on (K, M, D, contact, loads, supports)."""
    import hashlib

    h = hashlib.sha256()
    for A in (model.K, model.M, model.D):
        A = sp.csr_matrix(A)
        A.sort_indices()
        for a in (A.data, A.indices, A.indptr):
            h.update(np.ascontiguousarray(a).tobytes())
    c = model.contact
    for a in (c.dofs, c.partner_dofs, c.frame, c.area, c.gap, model.fixed_dofs,
              *[ld.vector for ld in model.loads]):
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


_SOLVED: dict[str, dict] = {}
#: K, M, D as pyNastran's double-precision field writer rounds them (print_scientific_double)
ROUNDED_BY_PYNASTRAN: dict = {}


def answers(model) -> dict:
    """Three modes with sliding flanks, one periodic solve, one wear step (solved once for
    models whose arrays are the same bit for bit: their answers are the same)."""
    key = fingerprint(model)
    if key not in _SOLVED:
        _SOLVED[key] = _answers(model)
    return {**_SOLVED[key], "same_bits_as": key[:12]}


def _answers(model) -> dict:
    f = modes(model, 3, interface="sliding").frequency_hz
    s = solve_periodic(model, BASIS, F_HZ, eps=1e12)
    w = simulate_wear(model, BASIS, F_HZ, options=WearOptions(max_steps=1)).final_wear
    return {"f": f, "U": s.U, "lam": s.lam, "wear": w, "success": bool(s.success)}


def rel(a, b) -> float:
    return float(np.abs(np.asarray(a) - np.asarray(b)).max() / np.abs(b).max())


def entry_rel(A, B) -> float:
    """The largest relative difference entry by entry over the nonzeros of ``B`` (and an
    entry of ``A`` where ``B`` has none counts as a relative difference of 1)."""
    A, B = sp.csr_matrix(A), sp.csr_matrix(B)
    D = (A - B).tocoo()
    b = B[D.row, D.col]
    b = b.toarray().ravel() if sp.issparse(b) else np.asarray(b).ravel()
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(b != 0, np.abs(D.data) / np.abs(b), np.where(D.data != 0, 1.0, 0.0))
    return float(r.max(initial=0.0))


def compare(name, m1, ref, answers_ref, t_read) -> dict:
    """K, M, D and the answers of ``m1`` against ``ref`` (the mesh model, rounded as the
    format holds its digits)."""
    a1 = answers(m1)
    row = {"format": name, "read_cpu_s": round(t_read, 2),
           **{f"{k}_rel": float(abs(getattr(m1, k) - getattr(ref, k)).max()
                                / abs(getattr(ref, k)).max()) for k in NAMES},
           **{f"{k}_entry_rel": entry_rel(getattr(m1, k), getattr(ref, k)) for k in NAMES},
           "modes_rel": rel(a1["f"], answers_ref["f"]),
           "U_rel": rel(a1["U"], answers_ref["U"]), "lam_rel": rel(a1["lam"], answers_ref["lam"]),
           "wear_rel": rel(a1["wear"], answers_ref["wear"]), "converged": a1["success"],
           "same_bits_as_reference": a1["same_bits_as"] == answers_ref["same_bits_as"]}
    print(json.dumps(row))
    return row


def superelement(m0, answers_ref) -> dict:
    """The dovetail as a Craig-Bampton superelement with every fixed-interface mode."""
    from fretwear.model.core import Load
    from fretwear.model.readers import FEMatrices, craig_bampton, superelement

    # the library refuses a dense eigenproblem above 2000 interior DOFs (minutes, 0.3 GB a
    # matrix): lifted here for the 5.6e3 of the dovetail
    superelement.DENSE_MODES_LIMIT = 10_000

    fe = FEMatrices(m0.K, m0.M, ff.dofmap_of(m0), D=m0.D)
    contact = ff.contacts_of(m0)
    boundary = np.concatenate([np.concatenate([c.nodes, c.partners]) for c in contact]
                              + [[m0.observed[0].dofs[0] // 3 + 1]])
    t = cpu()
    se = craig_bampton(fe, boundary, n_modes=None, fixed=m0.fixed_dofs)
    n_interior = int(se.fe.dofs.size - 3 * boundary.size)
    t_cb = cpu() - t
    loads = [Load(se.reduce(ld.vector), ld.waveform, ld.coefficients, ld.name)
             for ld in m0.loads]
    m1 = from_fe(se.fe, contact=contact, loads=loads, observed=ff.observed_of(m0))
    a1 = answers(m1)
    row = {"format": f"Craig-Bampton, all {n_interior} interior modes",
           "reduce_cpu_s": round(t_cb, 1), "dofs": int(se.fe.dofs.size),
           "modes_rel": rel(a1["f"], answers_ref["f"]),
           "U_rel": rel(a1["U"], answers_ref["U"]), "lam_rel": rel(a1["lam"], answers_ref["lam"]),
           "wear_rel": rel(a1["wear"], answers_ref["wear"]), "converged": a1["success"]}
    print(json.dumps(row))
    return row


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--pynastran", help="Python with pyNastran and NumPy < 2 (optional)")
    p.add_argument("--superelement", action="store_true",
                   help="also the Craig-Bampton superelement with every interior mode")
    p.add_argument("--formats", nargs="+", help="only these formats (e.g. 'ansys full'): "
                   "their rows replace those of the same name in the --out file")
    p.add_argument("--out", default=str(ROOT / "docs" / "studies" / "figures"
                                        / "dovetail-exports.json"))
    args = p.parse_args(argv)
    m0 = build_model(load_case(example_path("dovetail-frf")))
    m10 = dataclasses.replace(m0, K=ten_digits(m0.K), M=ten_digits(m0.M), D=ten_digits(m0.D))
    t = cpu()
    ref, ref10 = answers(m0), answers(m10)
    print(f"mesh model: modes {np.round(ref['f'], 1)} Hz, max wear {ref['wear'].max():.3e} m, "
          f"{cpu() - t:.1f} s CPU for both references")
    rows = [{"format": "mesh model rounded to 10 digits (the DMIG reference)",
             **{f"{k}_entry_rel": entry_rel(getattr(m10, k), getattr(m0, k)) for k in NAMES},
             "modes_rel": rel(ref10["f"], ref["f"]), "U_rel": rel(ref10["U"], ref["U"]),
             "lam_rel": rel(ref10["lam"], ref["lam"]),
             "wear_rel": rel(ref10["wear"], ref["wear"])}]
    print(json.dumps(rows[0]))
    with tempfile.TemporaryDirectory() as tmp:
        for name, (a, kw) in exports(m0, Path(tmp), args.pynastran).items():
            if args.formats and name not in args.formats:
                continue
            t = cpu()
            fe = read_fe(*a, **kw)
            t_read = cpu() - t
            # a .full holds K and M only: the hysteretic D given as a matrix (as exported
            # apart, e.g. Matrix Market), or the case's loss factor (D = eta K)
            damping = {"ansys full, D given": Damping(D=m0.D),
                       "ansys full, loss factor": Damping(loss_factor=LOSS_FACTOR)}.get(name)
            ten = name.startswith("dmig")
            r0, a0 = (m10, ref10) if ten else (m0, ref)
            if name == "dmig (pyNastran)":
                r0 = dataclasses.replace(m0, **{k: ROUNDED_BY_PYNASTRAN[NAMES[k]].tocsr()
                                                for k in NAMES})
                a0 = answers(r0)
            loss = name == "ansys full, loss factor"
            if loss:  # the mesh model's D leaves its springs undamped: D = eta K here
                r0 = dataclasses.replace(m0, D=sp.csr_matrix(LOSS_FACTOR * m0.K))
                a0 = answers(r0)
            m1 = rebuilt(m0, fe, damping)
            rows.append(compare(name, m1, r0, a0, t_read))
            if loss:  # and against the mesh model itself
                a1 = answers(m1)
                rows[-1].update({f"{k}_rel_to_mesh_model": rel(a1[k], ref[k])
                                 for k in ("f", "U", "lam", "wear")})
                print(json.dumps(rows[-1]))
    if args.superelement:
        rows.append(superelement(m0, ref))
    if args.formats:  # the other rows as the last full run left them
        old = json.loads(Path(args.out).read_text())["rows"]
        names = [r["format"] for r in rows[1:]]
        rows = [r for r in old if r["format"] not in names] + rows[1:]
    Path(args.out).write_text(json.dumps({"f_hz": F_HZ, "harmonics": 1, "rows": rows},
                                         indent=1) + "\n")


if __name__ == "__main__":
    main()
