"""Study files a hostile user writes: one of the four kinds (grid, samples, ensemble, split)
on a small valid base case, with one or two of its values replaced by a valid or invalid one
(the pools of tests/helpers/hostile.py), or a key path into the base case that does not exist.

Shared by the survey (studies/hostile_inputs.py --studies) and tests/test_hostile_cases.py.
Each study is run with ``fretwear study STUDY --collect``: read, validated against the base
case, expanded and sized, its members written and ``study.nc`` aggregated, without running the
members on a cluster (the runs of members are the case files' survey). What it must get: exit
0 (or 1) with ``study.nc``, or exit 2 with one line, never a traceback or a file outside the
output folder.
"""

from __future__ import annotations

import contextlib
import io
import tomllib
from pathlib import Path

from hypothesis import strategies as st

from helpers import hostile

#: one small valid body per kind (the base case is written beside the study as base.toml)
KINDS = {
    "grid": '[grid]\n"contact.mu" = [0.2, 0.3]\n',
    "tied": ('[grid]\n[[grid.tied]]\n"contact.mu" = [0.2, 0.3]\n'
             '"material.E" = [2.0e11, 2.1e11]\n'),
    "samples": ('[samples]\nn = 3\nseed = 1\n[samples.vary]\n'
                '"contact.mu" = {distribution = "uniform", low = 0.2, high = 0.4}\n'),
    "ensemble": ('[ensemble]\nmembers = 3\nseed = 1\n[ensemble.perturb]\n'
                 '"material.E" = {relative = 0.01}\n'),
    "split": "[split]\nchunks = 2\n",
}

#: the base analysis of each kind (a split divides a sweep's band)
BASE_ANALYSIS = {"split": "sweep"}

#: hostile values of study keys: sizes, seeds, distributions, paths
VALUES = (0, -1, 1, 2, 10**9, 40**6, 2**62, 10**400, 2.5, -2.5, 0.0, 1e308, "x", "", True,
          [], [1, 2], {"a": 1}, "../../../escape", "nowhere.mu", "contact.nowhere",
          "loads[9].pressure", "uniform", "normal", "loguniform", "latin_hypercube")

#: the value leaves a mutation picks from, by kind: (table path, key)
LEAVES = {
    "grid": [(("grid",), "contact.mu"), ((), "workers"), ((), "base"), ((), "scheduler"),
             (("set",), "analysis.n_modes"), (("output",), "figures")],
    "tied": [(("grid", "tied", 0), "contact.mu"), (("grid", "tied", 0), "material.E")],
    "samples": [(("samples",), "n"), (("samples",), "seed"), (("samples",), "method"),
                (("samples", "vary", "contact.mu"), "distribution"),
                (("samples", "vary", "contact.mu"), "low"),
                (("samples", "vary", "contact.mu"), "high"),
                (("samples", "vary", "contact.mu"), "std")],
    "ensemble": [(("ensemble",), "members"), (("ensemble",), "seed"),
                 (("ensemble",), "include_base"),
                 (("ensemble", "perturb", "material.E"), "relative"),
                 (("ensemble", "perturb", "material.E"), "absolute"),
                 (("ensemble", "perturb", "material.E"), "distribution")],
    "split": [(("split",), "chunks"), (("split",), "join_rtol")],
}


def base_study(kind: str) -> dict:
    """The valid study of ``kind`` (parsed TOML) on ``base.toml``."""
    return tomllib.loads('title = "hostile"\nbase = "base.toml"\n' + KINDS[kind])


@st.composite
def hostile_studies(draw) -> tuple[str, dict, list[str]]:
    """``(kind, study, changes)``: a study of a drawn kind with one or two values replaced."""
    kind = draw(st.sampled_from(sorted(KINDS)))
    study = base_study(kind)
    changes = []
    for _ in range(draw(st.integers(1, 2))):
        path, key = draw(st.sampled_from(LEAVES[kind]))
        value = draw(st.sampled_from(VALUES))
        node = study
        for k in path:
            node = node[k] if isinstance(k, int) else node.setdefault(k, {})
        node[key] = value
        changes.append(f"{'.'.join(map(str, path + (key,)))} = {value!r}"[:100])
    return kind, study, changes


def _toml(d: dict, prefix: str = "") -> str:
    """``d`` as TOML, nested tables as dotted headers, key paths quoted."""
    lines, tables = [], []
    for k, v in d.items():
        if isinstance(v, dict):
            tables.append((k, v))
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            tables.append((k, v))
        else:
            lines.append(f'"{k}" = {_value(v)}')
    out = "\n".join(lines) + "\n"
    for k, v in tables:
        name = f'{prefix}"{k}"'
        if isinstance(v, list):
            for item in v:
                out += f"[[{name}]]\n" + _toml(item, name + ".")
        else:
            out += f"[{name}]\n" + _toml(v, name + ".")
    return out


def _value(v) -> str:
    if isinstance(v, list) and not v:
        return "[]"
    text = hostile.toml_text({"k": v})  # '"k" = ...' or a table
    return text.split("=", 1)[1].strip()


def run_study_file(kind: str, study: dict, folder: Path) -> tuple[int | None, str, str]:
    """Write the base case and ``study`` in ``folder`` and run ``fretwear study --collect``
    in this process: ``(exit status or None, stderr, outcome)`` as
    :func:`helpers.hostile.run_generated`."""
    from fretwear import cli

    base = hostile.base_case(BASE_ANALYSIS.get(kind, "periodic"))
    (folder / "base.toml").write_text(hostile.toml_text(base))
    path = folder / "study.toml"
    path.write_text(_toml(study))
    err = io.StringIO()
    try:
        with hostile.cpu_time_limit(hostile.TIME_LIMIT), contextlib.redirect_stderr(err), \
                contextlib.redirect_stdout(io.StringIO()):
            rc = cli.main(["study", str(path), "-o", str(folder / "out"), "--collect",
                           "--no-progress"])
    except hostile.Hang:
        return None, err.getvalue(), "hang"
    except BaseException as exc:  # what would be a traceback on the command line
        return None, err.getvalue(), f"traceback: {type(exc).__name__}: {exc}"[:300]
    return rc, err.getvalue(), "message" if rc == 2 else "ran"
