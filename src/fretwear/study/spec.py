"""Study files: a TOML file naming a base case file and what varies; read and validated here.

A study is one of four kinds, chosen by the table it has (exactly one of them)::

    [grid]       every combination of the listed values of one or more case keys
    [samples]    n seeded random (or Latin hypercube) samples of case keys from distributions
    [ensemble]   n members that differ from the base case by a stated, seeded perturbation
    [split]      a frequency sweep split into chunks of its band, one member each

``[grid]`` may tie keys together: each ``[[grid.tied]]`` block lists keys whose values vary
together (the i-th value of each in one member), one axis of the combinations. A value may be
a vector (``loads.shake.traction = [[0, 1e6, 0], [0, 2e6, 0]]``), and one component of a
vector is named by its number counted from 1 (``loads.shake.traction.2``).

Case keys are written as dotted paths into the case file's tables, exactly as TOML nests them:
``contact.mu``, ``analysis.frequency``, ``damping.loss_factor``; a block of an array of tables
is named by its ``name`` (``loads.Q.pressure``) or by its number counted from 1 as in the
messages of case files (``"loads[2].pressure"``, quoted because of the brackets). ``[set]``
changes keys of every member (e.g. a shorter run). Every mistake is one
:class:`~fretwear.errors.InputError` naming the study file and the key.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fretwear.errors import InputError
from fretwear.io.case import read_toml
from fretwear.io.schema import (
    Context,
    Field,
    Flag,
    Integer,
    Number,
    Spec,
    Table,
    Text,
    exactly_one,
    show,
)
from fretwear.validate import path as file_path

KINDS = ("grid", "samples", "ensemble", "split")
DISTRIBUTIONS = ("uniform", "loguniform", "normal")
SAMPLING = ("random", "latin_hypercube")
PERTURBATIONS = ("normal", "uniform")



class _Free(Spec):
    """A table whose keys are case key paths (checked later, against the base case)."""

    def expected(self, plural: bool = False) -> str:
        return "tables" if plural else "a table"

    def matches(self, value) -> bool:
        return isinstance(value, Mapping)

    def check(self, value, path, ctx):
        if not isinstance(value, Mapping):
            self._type_error(value, path)
        return dict(value)


_FREE = _Free()

STUDY = Table(
    {
        "title": Field(Text(), "one line describing the study (figures, results)"),
        "base": Field(Text(), "the base case file (relative to the study file)", required=True),
        "scheduler": Field(Text(), "address of a running Dask scheduler (tcp://host:8786); "
                           "default: a local cluster on this machine's cores"),
        "workers": Field(Integer(lo=1), "worker processes of the local cluster (default: the "
                         "number of cores)"),
        "set": Field(_FREE, "case keys set in every member (key path = value)"),
        "grid": Field(_FREE, "case keys and their values; the members are every combination"),
        "samples": Field(_FREE, "seeded random samples of case keys"),
        "ensemble": Field(_FREE, "members differing by a seeded perturbation"),
        "split": Field(_FREE, "a sweep split into chunks of its band"),
        "output": Field(_FREE, "where to write"),
    },
    checks=(exactly_one(*KINDS),),
)

SAMPLES = Table({
    "n": Field(Integer(lo=1), "number of samples", required=True),
    "seed": Field(Integer(lo=0), "seed of the random generator", required=True),
    "method": Field(Text(SAMPLING), "independent random draws or a Latin hypercube",
                    default="random"),
})
DISTRIBUTION = Table({
    "distribution": Field(Text(DISTRIBUTIONS), "the distribution of the key", required=True),
    "low": Field(Number(), "uniform, loguniform: lower bound"),
    "high": Field(Number(), "uniform, loguniform: upper bound"),
    "mean": Field(Number(), "normal: mean"),
    "std": Field(Number(lo=0, lo_open=True), "normal: standard deviation"),
})
ENSEMBLE = Table({
    "members": Field(Integer(lo=1), "number of members", required=True),
    "seed": Field(Integer(lo=0), "seed of the random generator", required=True),
    "include_base": Field(Flag(), "member 0 is the unperturbed base case", default=True),
})
PERTURBATION = Table(
    {
        "relative": Field(Number(lo=0, lo_open=True), "value x (1 + relative z)"),
        "absolute": Field(Number(lo=0, lo_open=True), "value + absolute z (in the key's unit)"),
        "distribution": Field(Text(PERTURBATIONS), "z: standard normal or uniform in [-1, 1]",
                              default="normal"),
    },
    checks=(exactly_one("relative", "absolute"),),
)
SPLIT = Table({
    "chunks": Field(Integer(lo=2), "number of chunks of the band (one member each)",
                    required=True),
    "join_rtol": Field(Number(lo=0, lo_open=True), "largest relative difference of the "
                       "response amplitude where two chunks meet", default=1e-6),
})
OUTPUT = Table({
    "directory": Field(Text(), "results folder (relative to the study file); default "
                       '"<study name>-results" beside it'),
    "figures": Field(Flag(), "write the study's figures", default=True),
})

_INDEXED = re.compile(r"^(?P<name>[A-Za-z_][A-Za-z0-9_]*)\[(?P<index>\d+)\]$")


@dataclass
class Study:
    """A validated study file.

    Attributes
    ----------
    path : the study file (absolute).
    title : its title (the file name when it has none).
    base : the base case file (absolute).
    kind : "grid", "samples", "ensemble" or "split".
    set : key path -> value, set in every member.
    grid : key path -> list of values (kind "grid").
    tied : groups of key paths -> lists of values varied together (``[[grid.tied]]``).
    samples : the [samples] table and ``vary`` (key path -> distribution table).
    ensemble : the [ensemble] table and ``perturb`` (key path -> perturbation table).
    split : the [split] table.
    scheduler, workers : the Dask cluster to use (None: the defaults).
    output : the [output] table.
    """

    path: Path
    title: str
    base: Path
    kind: str
    text: str
    set: dict = field(default_factory=dict)
    grid: dict = field(default_factory=dict)
    tied: list = field(default_factory=list)
    samples: dict = field(default_factory=dict)
    ensemble: dict = field(default_factory=dict)
    split: dict = field(default_factory=dict)
    scheduler: str | None = None
    workers: int | None = None
    output: dict = field(default_factory=dict)

    @property
    def name(self) -> str:
        return self.path.stem

    def output_dir(self, override: Path | str | None = None) -> Path:
        """``override`` (relative to the working directory), else ``[output] directory``
        (relative to the study file), else ``<study name>-results`` beside the study file."""
        if override is not None:
            return Path(override).expanduser().resolve()
        d = self.output.get("directory")
        if d is None:
            return self.path.parent / f"{self.name}-results"
        d = Path(d).expanduser()
        return d if d.is_absolute() else (self.path.parent / d).resolve()


# --- key paths ------------------------------------------------------------------------------
def split_key(key: str) -> list[str]:
    """``"loads[2].pressure"`` -> ``["loads", "2", "pressure"]`` (numbers counted from 1);
    ``"loads.Q.pressure"`` -> ``["loads", "Q", "pressure"]``."""
    parts = []
    for part in str(key).split("."):
        m = _INDEXED.match(part)
        if m:
            parts += [m["name"], m["index"]]
        elif part:
            parts.append(part)
        else:
            raise InputError(f"key path {key!r}: an empty part between dots")
    return parts


def _flatten(table: Mapping, prefix: str, leaf) -> dict:
    """Dotted key paths of a nested TOML table; ``leaf(value)`` says where to stop."""
    out = {}
    for k, v in table.items():
        path = f"{prefix}.{k}" if prefix else str(k)
        if isinstance(v, Mapping) and not leaf(v):
            out.update(_flatten(v, path, leaf))
        else:
            out[path] = v
    return out


def _spec_leaf(keys):
    return lambda v: bool(set(v) & set(keys))


def _prefix(study_path: Path, where: str, exc: InputError) -> InputError:
    return InputError(f"{study_path.name}: {where}{exc}")


def _is_vector(v) -> bool:
    return isinstance(v, list) and bool(v) and all(
        isinstance(x, int | float) and not isinstance(x, bool) for x in v)


def _check_values(values, label: str) -> list:
    if not isinstance(values, list) or not values:
        raise InputError(f"{label} = {show(values)}: expected a non-empty list of values")
    for v in values:
        if isinstance(v, Mapping) or (isinstance(v, list) and not _is_vector(v)):
            raise InputError(f"{label} = {show(values)}: expected a list of numbers, strings, "
                             "booleans or vectors (lists of numbers, e.g. tractions "
                             "[[0, 1e6, 0], [0, 2e6, 0]])")
    return values


def _tied(groups, ctx_label: str = "grid.tied") -> list[dict]:
    """``[[grid.tied]]``: groups of keys whose lists of values vary together (the i-th value
    of each key in one member); each group is one axis of the grid's combinations."""
    if not isinstance(groups, list) or not all(isinstance(g, Mapping) for g in groups):
        raise InputError(f"{ctx_label} = {show(groups)}: expected an array of tables "
                         "([[grid.tied]]), each key path = [values] of the same length")
    out = []
    for j, group in enumerate(groups, start=1):
        label = f"[[grid.tied]] block {j}"
        flat = _flatten(group, "", lambda v: False)
        if len(flat) < 1:
            raise InputError(f"{label}: expected key path = [values] for at least one key")
        flat = {k: _check_values(v, f"{label}: {k}") for k, v in flat.items()}
        sizes = {k: len(v) for k, v in flat.items()}
        if len(set(sizes.values())) > 1:
            raise InputError(f"{label}: the lists differ in length ("
                             + ", ".join(f"{k}: {n}" for k, n in sizes.items())
                             + "); expected one value of each key per member")
        for key in flat:
            split_key(key)
        out.append(flat)
    return out


def _number(v, label: str) -> float:
    if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
        raise InputError(f"{label} = {show(v)}: expected a finite number")
    return float(v)


def _check_distribution(d: dict, label: str) -> dict:
    kind = d["distribution"]
    need = ("mean", "std") if kind == "normal" else ("low", "high")
    other = ("low", "high") if kind == "normal" else ("mean", "std")
    for k in need:
        if k not in d:
            raise InputError(f"{label}: distribution = {show(kind)} needs {need[0]} and "
                             f"{need[1]}")
        _number(d[k], f"{label}.{k}")
    for k in other:
        if k in d:
            raise InputError(f"{label}: {k} is not used with distribution = {show(kind)} "
                             f"(give {need[0]} and {need[1]})")
    if kind != "normal" and not d["low"] < d["high"]:
        raise InputError(f"{label}: low = {show(d['low'])}, high = {show(d['high'])}: expected "
                         "low < high")
    if kind == "loguniform" and d["low"] <= 0:
        raise InputError(f"{label}.low = {show(d['low'])}: expected a positive number "
                         "(loguniform)")
    return d


def read_study(path: Path | str) -> Study:
    """Read and validate a study file (the base case is read later, member by member).

    Raises
    ------
    InputError
        One line naming the study file and the key.
    """
    path = file_path(path, "path")
    path = Path(path).expanduser().resolve()
    try:
        text, raw = read_toml(path)
    except InputError as exc:
        raise InputError(str(exc).replace("case file", "study file")) from None
    ctx = Context(path.parent)
    try:
        top = STUDY.check(raw, "", ctx)
    except InputError as exc:
        raise _prefix(path, "", exc) from None
    kind = next(k for k in KINDS if k in top)
    base = Path(top["base"]).expanduser()
    base = base if base.is_absolute() else (path.parent / base).resolve()
    if not base.is_file():
        raise InputError(f"{path.name}: base = {show(top['base'])}: expected the path of an "
                         f"existing case file (no file at {base})")
    study = Study(path=path, title=top.get("title") or path.stem, base=base, kind=kind,
                  text=text, scheduler=top.get("scheduler"), workers=top.get("workers"))
    try:
        study.set = _flatten(top.get("set", {}), "", lambda v: False)
        for key in study.set:
            split_key(key)
        study.output = OUTPUT.check(top.get("output", {}), "output", ctx)
        if kind == "grid":
            table = dict(top["grid"])
            study.tied = _tied(table.pop("tied")) if "tied" in table else []
            grid = _flatten(table, "", lambda v: False)
            if not grid and not study.tied:
                raise InputError("[grid]: expected at least one key path = [values] (or a "
                                 "[[grid.tied]] group)")
            study.grid = {k: _check_values(v, f"grid.{k}") for k, v in grid.items()}
            for key in grid:
                split_key(key)
            both = set(grid).intersection(*[set(g) for g in study.tied]) if study.tied else ()
            keys = [k for g in study.tied for k in g] + list(grid)
            twice = sorted({k for k in keys if keys.count(k) > 1} | set(both))
            if twice:
                raise InputError(f"[grid]: {', '.join(twice)} varied twice (in [grid] and "
                                 "[[grid.tied]], or in two groups); expected each key once")
        elif kind == "samples":
            s = dict(top["samples"])
            vary = s.pop("vary", None)
            study.samples = SAMPLES.check(s, "samples", ctx)
            if not isinstance(vary, Mapping) or not vary:
                raise InputError("[samples.vary]: expected key path = {distribution = ..., "
                                 "...} for at least one case key")
            flat = _flatten(vary, "", _spec_leaf(DISTRIBUTION.fields))
            study.samples["vary"] = {
                k: _check_distribution(DISTRIBUTION.check(v, f"samples.vary.{k}", ctx),
                                       f"samples.vary.{k}")
                for k, v in flat.items()}
            for key in flat:
                split_key(key)
        elif kind == "ensemble":
            e = dict(top["ensemble"])
            perturb = e.pop("perturb", None)
            study.ensemble = ENSEMBLE.check(e, "ensemble", ctx)
            if not isinstance(perturb, Mapping) or not perturb:
                raise InputError("[ensemble.perturb]: expected key path = {relative = ...} or "
                                 "{absolute = ...} for at least one case key")
            flat = _flatten(perturb, "", _spec_leaf(PERTURBATION.fields))
            study.ensemble["perturb"] = {k: PERTURBATION.check(v, f"ensemble.perturb.{k}", ctx)
                                         for k, v in flat.items()}
            for key in flat:
                split_key(key)
        else:
            study.split = SPLIT.check(top["split"], "split", ctx)
    except InputError as exc:
        raise _prefix(path, "", exc) from None
    return study


def value_label(value: Any) -> str:
    """A varied value as it appears in member descriptions."""
    return f"{value:.6g}" if isinstance(value, float) else show(value)
