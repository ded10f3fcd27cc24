"""Case files a hostile user writes, generated from the schema itself.

Shared by the property-based tests (tests/test_hostile_cases.py) and the survey script
(studies/hostile_inputs.py). A generated case starts from one of a few small valid cases
(every analysis type, a mesh model or user matrices) and gets one to three keys replaced by a
value drawn for that key's specification: a valid one (inside the schema's type and bounds),
or an invalid one (a wrong type, NaN, infinities, zero, negative, far out of range, huge
integers, absurd sizes, path traversal and over-long names). The key paths come from the
schema tables (fretwear.io.case and the registered analyses), so a key added to the schema is
generated without touching this file.

What every generated case must get from ``fretwear run``: exit 0 (or 1: ran, some solve did
not converge) with a results file, or exit 2 with one line that names what is wrong, never a
traceback, never a file outside the output folder.
"""

from __future__ import annotations

import contextlib
import io
import math
import signal
import tomllib
from pathlib import Path

from hypothesis import strategies as st

from fretwear.io import case as case_schema
from fretwear.io.schema import (
    AnyOf,
    Choice,
    Dict,
    FilePath,
    Flag,
    Integer,
    ListOf,
    Number,
    Table,
    TableList,
    Text,
    Variant,
)

MODEL = """
[model]
type = "rectangle"
length = 0.02
height = 0.01
nx = 4
ny = 2
thickness = 0.01
[material]
E = 210e9
nu = 0.3
rho = 7800.0
[damping]
loss_factor = 0.01
[[springs]]
at = "bottom_left"
direction = "x"
stiffness = 1e7
[[loads]]
name = "P"
boundary = "top"
pressure = 1e6
[[loads]]
name = "Q"
boundary = "right"
pressure = 2e5
waveform = "cos"
[contact]
boundary = "bottom"
mu = 0.3
wear_coefficient = 1e-13
[observed]
Pe = [0.02, 0.005]
"""

#: one small, fast, valid [analysis] table per analysis type
ANALYSES = {
    "modes": 'type = "modes"\nn_modes = 4\n',
    "frf": 'type = "frf"\nf_min = 1e3\nf_max = 2e3\nn_points = 3\n',
    "periodic": 'type = "periodic"\nfrequency = 1500.0\nharmonics = 3\nn_samples = 16\n',
    "sweep": ('type = "sweep"\nf_min = 1000.0\nf_max = 1200.0\nn_points = 3\nharmonics = 1\n'
              'n_samples = 16\ntime_domain_periods = 10\n'),
    "nonlinear-modes": ('type = "nonlinear-modes"\namplitude_min = 1e-10\namplitude_max = 1e-9\n'
                        'n_amplitudes = 2\nharmonics = 1\nn_samples = 16\n'),
    "transient": ('type = "transient"\nfrequency = 1500.0\nmode = "fixed"\nn_periods = 5\n'
                  'steps_per_period = 64\nmax_periods = 20\n'),
    "wear": ('type = "wear"\nquasi_static = true\nharmonics = 1\nn_samples = 16\n'
             'max_steps = 3\n'),
    "incremental-wear": 'type = "incremental-wear"\nn_cycles = 3\nsteps_per_cycle = 16\n',
    "worn-state": ('type = "worn-state"\nquasi_static = true\nharmonics = 1\nn_samples = 16\n'
                   'max_steps = 3\n'),
    "cyclic-modes": 'type = "cyclic-modes"\nn_modes = 2\n',
}

#: the analyses run on a bladed-disk sector (:data:`SECTOR_FILES`, tests/helpers/cyclic.py)
SECTOR_ANALYSES = ("cyclic-modes",)
#: the files a sector case needs beside it (written by :func:`run_generated`)
SECTOR_FILES = ("sector.msh", "sector.toml")

#: time limit of one generated run [s of CPU time of this process]; a run that takes longer
#: counts as a hang (CPU, not wall time: on a machine loaded by other work a run can wait
#: minutes for a core without computing more)
TIME_LIMIT = 60

HUGE_INT = 10**400
ABSURD_COUNTS = (10**9, 10**12, 2**62)
INVALID_NUMBERS = (math.nan, math.inf, -math.inf, 1e308, -1e308, 1e-308, 1e-300, 0.0, -1.0,
                   -1e-12, HUGE_INT, -HUGE_INT)
INVALID_OTHER = ("", "x", "../../../escape", "a/b", "y" * 400, True, False, [], [1, 2, 3],
                 {"a": 1})


def base_case(analysis: str) -> dict:
    """A small valid case (parsed TOML) with the given analysis type (on the annulus sector
    of tests/helpers/cyclic.py for :data:`SECTOR_ANALYSES`)."""
    if analysis in SECTOR_ANALYSES:
        import tempfile

        from helpers.cyclic import write_sector_case

        with tempfile.TemporaryDirectory() as tmp:
            path, _ = write_sector_case(Path(tmp), n_sectors=8, engine_order=1)
            text = path.read_text()
        return tomllib.loads(text + "[analysis]\n" + ANALYSES[analysis])
    return tomllib.loads(MODEL + "[analysis]\n" + ANALYSES[analysis])


def _spec_values(spec, data) -> object:
    """A value for ``spec``: valid (inside its type and bounds) or not, drawn by ``data``."""
    if isinstance(spec, AnyOf):
        return _spec_values(data.draw(st.sampled_from(spec.options)), data)
    invalid = data.draw(st.booleans())
    if invalid:
        pool = list(INVALID_NUMBERS + INVALID_OTHER)
        if isinstance(spec, Integer):
            pool += list(ABSURD_COUNTS) + [2.5, -3]
        return data.draw(st.sampled_from(pool))
    if isinstance(spec, Integer):
        lo = int(spec.lo) if spec.lo is not None else -5
        return data.draw(st.integers(lo, max(lo, min(int(spec.hi or 64), 64))))
    if isinstance(spec, Number):
        lo = -1e9 if spec.lo is None else spec.lo
        hi = 1e12 if spec.hi is None else spec.hi
        return data.draw(st.floats(lo, hi, allow_nan=False, allow_infinity=False,
                                   exclude_min=spec.lo_open, exclude_max=spec.hi_open))
    if isinstance(spec, Choice):
        return data.draw(st.sampled_from(spec.values))
    if isinstance(spec, Flag):
        return data.draw(st.booleans())
    if isinstance(spec, Text):
        if spec.choices:
            return data.draw(st.sampled_from(list(spec.choices)))
        return data.draw(st.text(min_size=1, max_size=20))
    if isinstance(spec, ListOf):
        n = data.draw(st.sampled_from(spec.sizes)) if spec.sizes else data.draw(
            st.integers(1 if spec.non_empty else 0, 4))
        return [_spec_values(spec.item, data) for _ in range(n)]
    if isinstance(spec, FilePath):
        return data.draw(st.sampled_from(["missing.msh", "/dev/null", "."]))
    return data.draw(st.sampled_from(INVALID_OTHER))


def _tables(case: dict) -> list[tuple[tuple, Table]]:
    """(key path of a table in ``case``, its schema) for every table the case has."""
    from fretwear.analyses.registry import analysis_tables

    if "cyclic" in case:
        out = [(("model",), case_schema.MODEL_TYPES[case["model"]["type"]]),
               (("material",), case_schema.MATERIAL), (("cyclic",), case_schema.CYCLIC),
               (("analysis",), analysis_tables()[case["analysis"]["type"]])]
        for i in range(len(case.get("loads", []))):
            out.append((("loads", i), case_schema.LOAD_MESH))
        return out
    out = [(("model",), case_schema.MODEL_TYPES[case["model"]["type"]]),
           (("material",), case_schema.MATERIAL), (("damping",), case_schema.DAMPING),
           (("contact",), case_schema.CONTACT_MESH), (("output",), case_schema.OUTPUT),
           (("analysis",), analysis_tables()[case["analysis"]["type"]])]
    for i in range(len(case.get("loads", []))):
        out.append((("loads", i), case_schema.LOAD_MESH))
    for i in range(len(case.get("springs", []))):
        out.append((("springs", i), case_schema.SPRING))
    return out


#: changes aimed at the keys of materials per body and connectors, whose meaning depends on
#: other keys (a set holding no whole cell, a waveform without its load, a partner that is the
#: boundary itself): (key path, value)
MEANINGS = (
    (("materials", "top"), {"E": 210e9, "nu": 0.3, "rho": 7800.0}),
    (("materials", "bottom_left"), {"E": 210e9, "nu": 0.3, "rho": 7800.0}),
    (("materials", "nowhere"), {"E": 210e9, "nu": 0.3, "rho": 7800.0}),
    (("contact", "normal_waveform"), "cos"),
    (("contact", "normal_pressure"), -1e6),
    (("contact", "normal_pressure"), math.nan),
    (("contact", "partner"), "bottom"),
    (("contact", "partner"), "top"),
    (("contact", "tolerance"), 1e-3),
    (("contact", "normal_stiffness"), 0.0),
    (("contact", "tangential_stiffness"), -1.0),
    (("contact", "partner_wear_coefficient"), 1e-13),
    (("material", "E"), 210.0),
)


def _get(case: dict, path: tuple):
    node = case
    for k in path:
        node = node.setdefault(k, {}) if isinstance(k, str) else node[k]
    return node


@st.composite
def hostile_cases(draw, analyses=tuple(ANALYSES)) -> tuple[dict, list[str]]:
    """A generated case (parsed TOML) and the list of changes made (for the report)."""
    data = draw(st.data())
    case = base_case(draw(st.sampled_from(analyses)))
    tables = _tables(case)
    changes = []
    for _ in range(draw(st.integers(1, 3))):
        path, table = draw(st.sampled_from(tables))
        keys = [k for k in table.fields if not isinstance(table.fields[k].spec,
                                                          Table | TableList | Dict | Variant)]
        if path == ("output",):
            keys = [k for k in keys if k != "directory"]  # the test chooses the folder
        if not keys:
            continue
        key = draw(st.sampled_from(sorted(keys)))
        value = _spec_values(table.fields[key].spec, data)
        _get(case, path)[key] = value
        changes.append(f"{'.'.join(map(str, path))}.{key} = {value!r}"[:120])
    if "cyclic" not in case and draw(st.integers(0, 3)) == 0:  # one in four: a key whose
        # meaning depends on others (of the rectangle's tables)
        path, value = draw(st.sampled_from(MEANINGS))
        _get(case, path[:-1])[path[-1]] = value
        changes.append(f"{'.'.join(path)} = {value!r}")
    return case, changes


def toml_text(case: dict) -> str:
    """``case`` written as TOML (the subset the generator makes)."""
    def value(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, int):
            return str(v)
        if isinstance(v, float):
            return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(
                v) else repr(v)
        if isinstance(v, str):
            return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
        if isinstance(v, list):
            return "[" + ", ".join(value(x) for x in v) + "]"
        if isinstance(v, dict):
            return "{" + ", ".join(f"{k} = {value(x)}" for k, x in v.items()) + "}"
        raise TypeError(v)

    lines = []
    for k, v in case.items():
        if not isinstance(v, dict | list) or (isinstance(v, list) and v and not isinstance(
                v[0], dict)):
            lines.append(f"{k} = {value(v)}")
    for k, v in case.items():
        if isinstance(v, dict):
            lines.append(f"[{k}]")
            lines += [f'"{kk}" = {value(vv)}' for kk, vv in v.items()]
        elif isinstance(v, list) and v and isinstance(v[0], dict):
            for item in v:
                lines.append(f"[[{k}]]")
                lines += [f'"{kk}" = {value(vv)}' for kk, vv in item.items()]
    return "\n".join(lines) + "\n"


class Hang(Exception):
    """A generated run took longer than :data:`TIME_LIMIT`."""


@contextlib.contextmanager
def cpu_time_limit(seconds: float):
    """Raise :class:`Hang` in the body once it has used ``seconds`` of CPU time (SIGPROF)."""
    old = signal.signal(signal.SIGPROF, _alarm)
    signal.setitimer(signal.ITIMER_PROF, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)
        signal.signal(signal.SIGPROF, old)


def _alarm(signum, frame):
    raise Hang


def run_generated(case: dict, folder: Path) -> tuple[int | None, str, str]:
    """Run ``case`` with ``fretwear run`` in this process, as the command line does:
    ``(exit status or None, stderr, outcome)`` with outcome one of "ran", "message",
    "traceback: <exception>", "hang"."""
    from fretwear import cli

    path = folder / "case.toml"
    path.write_text(toml_text(case))
    if case.get("model", {}).get("file") == SECTOR_FILES[0]:
        from helpers.cyclic import write_sector_case

        write_sector_case(folder, n_sectors=8, engine_order=1)  # the mesh file it reads
    err = io.StringIO()
    try:
        with cpu_time_limit(TIME_LIMIT), contextlib.redirect_stderr(err), \
                contextlib.redirect_stdout(io.StringIO()):
            rc = cli.main(["run", str(path), "-o", str(folder / "out"), "--no-progress"])
    except Hang:
        return None, err.getvalue(), "hang"
    except BaseException as exc:  # what would be a traceback on the command line
        return None, err.getvalue(), f"traceback: {type(exc).__name__}: {exc}"[:300]
    return rc, err.getvalue(), "message" if rc == 2 else "ran"
