"""The members of a study: the base case with the varied keys set, as complete case files.

:func:`expand` turns a :class:`~fretwear.study.spec.Study` into its list of :class:`Member`
(a grid's combinations, seeded samples, seeded ensemble perturbations, chunks of a sweep);
:func:`member_cases` applies each member's values to the base case, validates the result as a
case file (the same validation as ``fretwear run``, so a bad key or value gets the same
one-line message, prefixed with the study file and the member) and writes its case text. A
member's case file is self-contained (file paths made absolute, no ``[output] directory``):
``fretwear run member-0003/case.toml -o DIR`` reruns it by hand, bit for bit.
"""

from __future__ import annotations

import copy
import itertools
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import tomli_w

from fretwear.analyses.registry import analysis_tables
from fretwear.errors import InputError
from fretwear.io.case import read_toml, validate
from fretwear.io.schema import show
from fretwear.resources import require_memory
from fretwear.study.spec import Study, split_key, value_label

CASE_FILE = "case.toml"


@dataclass
class Member:
    """One member: ``index`` (from 0), the values of the varied keys (key path -> value)
    and, once built, its case text."""

    index: int
    values: dict
    text: str = ""
    analysis: dict = field(default_factory=dict)

    @property
    def folder_name(self) -> str:
        return f"member-{self.index:04d}"

    def describe(self) -> str:
        return ", ".join(f"{k} = {value_label(v)}" for k, v in self.values.items()) or "base"


# --- key paths in a case ------------------------------------------------------------------
def _locate(raw: dict, parts: list[str], key: str):
    """The table holding the last part of ``parts`` in ``raw`` (tables created as needed)."""
    node, i = raw, 0
    while i < len(parts) - 1:
        part, here = parts[i], ".".join(parts[: i + 1])
        child = node.get(part)
        if isinstance(child, list) and not all(isinstance(b, Mapping) for b in child):
            return _component(child, parts, i, key)
        if isinstance(child, list):  # an array of tables: a block by name or number from 1
            if i + 2 > len(parts) - 1:
                raise InputError(f"{key}: {part} is an array of tables; name a block and a "
                                 f"key ({part}.NAME.KEY or \"{part}[N].KEY\")")
            sel = parts[i + 1]
            names = [str(b.get("name")) for b in child if isinstance(b, Mapping)]
            if sel.isdigit():
                n = int(sel)
                if not 1 <= n <= len(child):
                    raise InputError(f"{key}: the base case has {len(child)} [[{part}]] "
                                     f"blocks; expected a number from 1 to {len(child)}")
                node = child[n - 1]
            elif sel in names:
                node = child[names.index(sel)]
            else:
                raise InputError(f"{key}: the base case has no [[{part}]] block named "
                                 f"{sel!r} (names: {', '.join(names) or 'none'})")
            i += 2
            continue
        if child is None:
            child = node[part] = {}
        elif not isinstance(child, Mapping):
            raise InputError(f"{key}: {here} = {show(child)} is a value, not a table")
        node, i = child, i + 1
    return node, parts[-1]


def _component(vector: list, parts: list[str], i: int, key: str):
    """The vector ``parts[i]`` and the index of its component ``parts[i + 1]`` (counted from
    1), the last part of ``key``."""
    here = ".".join(parts[: i + 1])
    rest = parts[i + 1:]
    n = len(vector)
    if len(rest) != 1 or not rest[0].isdigit() or not 1 <= int(rest[0]) <= n:
        raise InputError(f"{key}: {here} = {show(vector)} is a vector of {n} components; "
                         f"expected {here} (the whole vector) or {here}.N, N a component "
                         f"number from 1 to {n}")
    return vector, int(rest[0]) - 1


def get_key(raw: dict, key: str):
    """The value of ``key`` (a dotted path) in the parsed case ``raw`` (None if absent)."""
    table, last = _locate(copy.deepcopy(raw), split_key(key), key)
    if isinstance(table, list):
        return table[last]
    return table.get(last)


def set_key(raw: dict, key: str, value) -> None:
    """Set ``key`` (a dotted path) in the parsed case ``raw``."""
    table, last = _locate(raw, split_key(key), key)
    table[last] = value


# --- expanding a study ------------------------------------------------------------------------
def _grid(study: Study) -> list[dict]:
    """Every combination of the axes: each ``[grid]`` key alone, each tied group together."""
    axes = [[{k: v} for v in values] for k, values in study.grid.items()]
    for group in getattr(study, "tied", []):
        n = len(next(iter(group.values())))
        axes.append([{k: group[k][i] for k in group} for i in range(n)])
    return [{k: v for part in combo for k, v in part.items()}
            for combo in itertools.product(*axes)]


def _uniform_draws(n: int, d: int, seed: int, method: str) -> np.ndarray:
    if method == "latin_hypercube":
        from scipy.stats import qmc

        return qmc.LatinHypercube(d=d, seed=np.random.default_rng(seed)).random(n)
    return np.random.default_rng(seed).random((n, d))


def _samples(study: Study) -> list[dict]:
    from scipy.stats import norm

    vary = study.samples["vary"]
    u = _uniform_draws(study.samples["n"], len(vary), study.samples["seed"],
                       study.samples["method"])
    out = [{} for _ in range(u.shape[0])]
    for j, (key, d) in enumerate(vary.items()):
        if d["distribution"] == "uniform":
            x = d["low"] + u[:, j] * (d["high"] - d["low"])
        elif d["distribution"] == "loguniform":
            x = np.exp(np.log(d["low"]) + u[:, j] * (np.log(d["high"]) - np.log(d["low"])))
        else:
            x = d["mean"] + d["std"] * norm.ppf(u[:, j])
        for i in range(u.shape[0]):
            out[i][key] = float(x[i])
    return out


def _perturb(value, spec: dict, rng: np.random.Generator, key: str):
    """``value`` (a number or a list of numbers, each perturbed independently)."""
    if isinstance(value, list):
        return [_perturb(v, spec, rng, key) for v in value]
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise InputError(f"ensemble.perturb.{key}: the base case value {show(value)} is not a "
                         "number")
    z = rng.standard_normal() if spec["distribution"] == "normal" else rng.uniform(-1.0, 1.0)
    if "relative" in spec:
        return float(value) * (1.0 + spec["relative"] * z)
    return float(value) + spec["absolute"] * z


def _ensemble(study: Study, base: dict) -> list[dict]:
    e = study.ensemble
    out = []
    for i in range(e["members"]):
        if i == 0 and e["include_base"]:
            out.append({})
            continue
        rng = np.random.default_rng([e["seed"], i])  # member i's draws do not depend on n
        values = {}
        for key, spec in e["perturb"].items():
            current = get_key(base, key)
            if current is None:
                raise InputError(f"ensemble.perturb.{key}: the base case has no value to "
                                 "perturb (set it in the base case or in [set])")
            values[key] = _perturb(current, spec, rng, key)
        out.append(values)
    return out


def _chunks(study: Study, base: dict) -> list[dict]:
    """The sweep band cut into chunks of the base's frequency grid; neighbours share their
    end frequency (the join, checked after the run). Every chunk takes its eps from the whole
    band (``eps_band``): the "contact" or "top" rule's median over a chunk's own band would
    differ from chunk to chunk, and the joins with it."""
    a = validate(base, analysis_tables(), study.base.parent)["analysis"]
    if a["type"] != "sweep":
        raise InputError(f"[split] needs a sweep as base case; {study.base.name} has "
                         f"analysis.type = {show(a['type'])}")
    n, chunks = a["n_points"], study.split["chunks"]
    if n < 2 * chunks:
        raise InputError(f"split.chunks = {chunks}: the base sweep has {n} points; expected at "
                         f"most {n // 2} chunks (two points each at least)")
    grid = (np.geomspace if a["spacing"] == "log" else np.linspace)(a["f_min"], a["f_max"], n)
    edges = np.linspace(0, n - 1, chunks + 1).round().astype(int)
    band = a.get("eps_band") or [float(a["f_min"]), float(a["f_max"])]
    return [{"analysis.f_min": float(grid[i0]), "analysis.f_max": float(grid[i1]),
             "analysis.n_points": int(i1 - i0 + 1), "analysis.eps_band": band}
            for i0, i1 in itertools.pairwise(edges)]


def _absolute_paths(raw, checked):
    """``raw`` with every file path replaced by the absolute path validation resolved."""
    if isinstance(raw, Mapping) and isinstance(checked, Mapping):
        return {k: _absolute_paths(v, checked.get(k)) for k, v in raw.items()}
    if isinstance(raw, list) and isinstance(checked, list) and len(raw) == len(checked):
        return [_absolute_paths(r, c) for r, c in zip(raw, checked, strict=True)]
    if isinstance(raw, str) and isinstance(checked, Path):
        return str(checked)
    return raw


def member_case(base: dict, values: dict, base_dir: Path):
    """The parsed case of a member (``base`` with ``values`` set, file paths absolute, no
    ``[output] directory``) and its validated tables."""
    raw = copy.deepcopy(base)
    for key, value in values.items():
        set_key(raw, key, value)
    if isinstance(raw.get("output"), dict):
        raw["output"].pop("directory", None)
    checked = validate(raw, analysis_tables(), base_dir)
    return _absolute_paths(raw, checked), checked


#: the most members a study may have: each is a folder, a case text, a Dask task and a row of
#: study.nc; a million already takes hours of bookkeeping alone
MAX_MEMBERS = 1_000_000
#: memory the client holds per member (its case text, record, task and row of study.nc) [bytes]
MEMBER_BYTES = 64 * 1024


def member_count(study: Study) -> int:
    """The number of members ``study`` expands to, without expanding it."""
    if study.kind == "grid":
        return int(np.prod([len(v) for v in study.grid.values()], dtype=object))
    if study.kind == "samples":
        return int(study.samples["n"])
    if study.kind == "ensemble":
        return int(study.ensemble["members"])
    return int(study.split["chunks"])


def check_size(study: Study) -> int:
    """The member count of ``study``, after refusing (before anything is allocated) a study of
    more than :data:`MAX_MEMBERS` members or whose bookkeeping cannot fit in memory."""
    n = member_count(study)
    if n > MAX_MEMBERS:
        raise InputError(f"{study.path.name}: {n:.3g} members; expected at most "
                         f"{MAX_MEMBERS:,} (split the study, or vary fewer values)")
    require_memory(n * MEMBER_BYTES, f"{study.path.name}: a study of {n:,} members")
    return n


def expand(study: Study) -> list[Member]:
    """The members of ``study``, each with its case text; every bad key or value is one
    InputError naming the study file, the member and the key."""
    _, base = read_toml(study.base)
    name = study.path.name
    check_size(study)
    try:
        fixed, _ = member_case(base, study.set, study.base.parent)
    except InputError as exc:
        raise InputError(f"{name}: [set] on {study.base.name}: {exc}") from None
    try:
        values = {"grid": lambda: _grid(study), "samples": lambda: _samples(study),
                  "ensemble": lambda: _ensemble(study, fixed),
                  "split": lambda: _chunks(study, fixed)}[study.kind]()
    except InputError as exc:
        raise InputError(f"{name}: {exc}") from None
    members = []
    for i, v in enumerate(values):
        m = Member(i, v)
        try:
            raw, checked = member_case(fixed, v, study.base.parent)
        except InputError as exc:
            raise InputError(f"{name}: member {i} ({m.describe()}): {exc}") from None
        header = (f"# fretwear study {study.title!r}: member {i} of {len(values)} "
                  f"({m.describe()})\n# base case: {study.base}\n")
        m.text = header + tomli_w.dumps(raw)
        m.analysis = checked["analysis"]
        members.append(m)
    return members
