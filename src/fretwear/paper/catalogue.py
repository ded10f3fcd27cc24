"""The runs of the reproduction of Salles et al. (2011): which shipped example, with which
edits, for which of the paper's figures (:data:`RUNS`), and how a run's case text is made.

Plain data read by both :mod:`fretwear.paper.runs` (which runs them) and
:mod:`fretwear.paper.report` (which compares their results with the paper).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from fretwear.errors import InputError
from fretwear.examples import example_path

#: numerics of the quick wear runs (the model part of each file is kept as shipped)
QUICK_WEAR = {"harmonics": 3, "n_samples": 32, "tolerance": 5e-2}
#: shorter time integrations where the quick 70 and 79 kHz runs have no periodic balance
QUICK_TIME_DOMAIN = {"time_domain_settle": 100, "time_domain_average": 100}
#: load stepping and the short DLFT run it is compared with (paper Fig. 5): cycles, jump
STROMBERG_CYCLES = 2000
STROMBERG_JUMP = 2
#: the FRFs of the mesh comparison (paper Fig. 15), 30 and 100 contact elements
MESH_FRF = {"f_min": 1e4, "f_max": 1e5, "n_points": 46, "harmonics": 1, "n_samples": 16}
QUICK_MESH_FRF = {"f_min": 2e4, "f_max": 4e4, "n_points": 11}
#: the FRF before / after wear at 79 kHz (paper Fig. 24): band [Hz] and points
FRF_WORN_BAND = (6e4, 1e5, 41)


@dataclass(frozen=True)
class Run:
    """One run of the reproduction: a shipped example with edits.

    key : folder name in the work directory and name in the report.
    example : the shipped case file (``fretwear example list``).
    figures : the paper's figures it reproduces.
    analysis, model : edits of the ``[analysis]`` and ``[model]`` tables (full reproduction).
    quick, quick_model : the edits in quick mode (on top of ``analysis`` / ``model``).
    why : why the edits (shown in the report).
    """

    key: str
    example: str
    figures: str
    analysis: dict = field(default_factory=dict)
    model: dict = field(default_factory=dict)
    quick: dict = field(default_factory=dict)
    quick_model: dict = field(default_factory=dict)
    why: str = ""


RUNS: tuple[Run, ...] = (
    Run("frf", "salles2011-frf", "14, 22",
        quick={"f_min": 2e4, "f_max": 4e4, "n_points": 21, "harmonics": 1, "n_samples": 16},
        why="as shipped: 1 Hz-100 kHz, 200 log-spaced points, 7 harmonics, 128 samples"),
    Run("frf-mesh30", "salles2011-frf", "15", analysis=MESH_FRF, quick=QUICK_MESH_FRF,
        why="10-100 kHz, 46 points, 1 harmonic, 16 samples: the reference of frf-mesh100"),
    Run("frf-mesh100", "salles2011-frf", "15", analysis=MESH_FRF, model={"nx": 100},
        quick=QUICK_MESH_FRF,
        why="as frf-mesh30 with 100 contact elements (with 7 harmonics a solve has 3030 "
            "unknowns and the sweep takes hours: the mesh is compared at equal, reduced "
            "numerics)"),
    Run("wear-79khz", "salles2011-79khz", "17-21, 23d, 25",
        quick={**QUICK_WEAR, "max_steps": 3, **QUICK_TIME_DOMAIN},
        why="as shipped (stop at 2e8 cycles)"),
    Run("wear-79khz-explicit", "salles2011-79khz", "17-21, 25",
        analysis={"scheme": "explicit", "adaptive": False, "initial_jump": 1e7},
        quick={**QUICK_WEAR, "max_steps": 3, **QUICK_TIME_DOMAIN, "initial_jump": 1e5},
        why="the paper's slow-scale scheme: explicit Euler with fixed jumps of 1e7 cycles "
            "(section 4.2.3), to 2e8 cycles"),
    Run("wear-70khz", "salles2011-70khz", "23c, 25",
        quick={**QUICK_WEAR, "max_steps": 3, **QUICK_TIME_DOMAIN},
        why="as shipped (stop at 2e8 cycles)"),
    Run("wear-35khz", "salles2011-35khz", "25",
        quick={**QUICK_WEAR, "max_steps": 3}, why="as shipped (stop at 2e8 cycles)"),
    Run("wear-30khz", "salles2011-30khz", "23b, 25",
        quick={**QUICK_WEAR, "max_steps": 3}, why="as shipped (stop at 2e8 cycles)"),
    Run("stromberg", "stromberg1997", "5", quick=QUICK_WEAR,
        why="as shipped: 7 harmonics, 64 samples, sinusoidal Q, to the plateau"),
    Run("stromberg-triangle", "stromberg1997-triangle", "5", quick=QUICK_WEAR,
        why="as shipped: Stromberg's linear (triangle) evolution of Q, 15 harmonics, 128 "
            "samples, to the plateau"),
    Run("stromberg-2000", "stromberg1997", "5",
        analysis={"max_cycles": float(STROMBERG_CYCLES), "tolerance": 1e-3},
        quick={**QUICK_WEAR, "max_cycles": 200.0},
        why=f"stopped at {STROMBERG_CYCLES} cycles with a tight slow-scale tolerance (1e-3), "
            "for the comparison with load stepping"),
    Run("wear-quasistatic", "salles2011-quasistatic", "6-13, 23a, 25",
        quick={**QUICK_WEAR, "max_cycles": 1e12}, why="as shipped"),
    Run("periodic-79khz", "salles2011-79khz-periodic", "16 b, d", why="as shipped"),
    Run("periodic-10khz", "salles2011-79khz-periodic", "16 a, c",
        analysis={"frequency": 1e4}, quick={"harmonics": 3, "n_samples": 32},
        why="the same file at 10 kHz"),
)
RUN_KEYS = tuple(r.key for r in RUNS)
#: computations that are not case files, run after the case files they need
EXTRA_KEYS = ("stromberg-load-stepping", "frf-worn-79khz")


# --- editing case files -----------------------------------------------------------------------
def toml_value(value) -> str:
    """``value`` written as a TOML value (numbers, booleans, strings, lists of them)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, list | tuple):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    raise InputError(f"cannot write {value!r} into a case file; expected a number, a boolean, "
                     "a string or a list of them")


def edit_case_text(text: str, section: str, changes: dict) -> str:
    """The case file ``text`` with the keys ``changes`` of table ``[section]`` set: a line
    ``key = ...`` of the table is replaced (its comment dropped), a missing key is appended
    to the table. Only single-line values are replaced."""
    if not changes:
        return text
    lines = text.splitlines()
    header = f"[{section}]"
    try:
        start = next(i for i, ln in enumerate(lines) if ln.split("#")[0].strip() == header)
    except StopIteration:
        raise InputError(f"the case file has no table {header} to edit") from None
    end = next((i for i in range(start + 1, len(lines)) if lines[i].lstrip().startswith("[")),
               len(lines))
    todo = dict(changes)
    for i in range(start + 1, end):
        key = lines[i].split("=")[0].strip() if "=" in lines[i].split("#")[0] else None
        if key in todo:
            lines[i] = f"{key} = {toml_value(todo.pop(key))}"
    while end > start + 1 and not lines[end - 1].strip():
        end -= 1
    extra = [f"{k} = {toml_value(v)}" for k, v in todo.items()]
    lines[end:end] = extra
    return "\n".join(lines) + "\n"


def run_case_text(run: Run, quick: bool) -> str:
    """The case file text of ``run`` (the shipped example with the run's edits)."""
    text = example_path(run.example).read_text(encoding="utf-8")
    model = {**run.model, **(run.quick_model if quick else {})}
    analysis = {**run.analysis, **(run.quick if quick else {})}
    text = edit_case_text(text, "model", model)
    text = edit_case_text(text, "analysis", analysis)
    header = (f"# fretwear reproduce: run {run.key!r} (paper Fig. {run.figures}), the shipped "
              f"example {run.example!r}" + (" in quick mode" if quick else "") + "\n")
    return header + text
