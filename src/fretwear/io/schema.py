"""Declarative validation of nested TOML tables, with messages that name the key path.

A schema is a tree of value specifications (:class:`Spec` subclasses). A :class:`Table` maps
key names to :class:`Field` objects (a spec plus a description, a unit, a default and whether
the key is required). Validating a value returns a *normalised* copy (defaults filled in,
``"inf"`` turned into ``math.inf``, relative paths resolved) or raises one
:class:`~fretwear.errors.InputError` whose message names the key path, the value given and
what is expected, e.g.::

    material.nu = 0.5: expected a number in (-1, 0.5)
    unknown key 'materal' in [top level]; expected one of: model, material, ...
    (did you mean 'material'?)

The descriptions are also the documentation: :func:`render_table` writes a Markdown table of
a :class:`Table`. Items of arrays of tables are numbered from 1 in messages (``loads[2]`` is
the second ``[[loads]]`` block), as a user counts them in the file.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fretwear.errors import InputError

MISSING: Any = type("_Missing", (), {"__repr__": lambda self: "MISSING"})()
"""Sentinel: a field with no default (absent optional keys are left out of the output)."""


# --- messages -------------------------------------------------------------------------
def show(value: Any, limit: int = 60) -> str:
    """A value written the way it looks in a TOML file (truncated to ``limit`` characters)."""
    if isinstance(value, bool):
        text = "true" if value else "false"
    elif isinstance(value, str):
        text = '"' + value.replace('"', '\\"') + '"'
    elif isinstance(value, float) and math.isinf(value):
        text = "inf" if value > 0 else "-inf"
    elif isinstance(value, list | tuple):
        text = "[" + ", ".join(show(v, limit) for v in value) + "]"
    elif isinstance(value, Mapping):
        text = "{" + ", ".join(f"{k} = {show(v, limit)}" for k, v in value.items()) + "}"
    else:
        text = str(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def type_name(value: Any) -> str:
    """The TOML name of a value's type, for 'got a ...' in messages."""
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, int):
        return "an integer"
    if isinstance(value, float):
        return "a number"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, Mapping):
        return "a table"
    if isinstance(value, list | tuple):
        return "a list"
    return type(value).__name__


def suggest(word: str, choices, quote: Callable[[str], str] = repr) -> str:
    """``" (did you mean 'x'?)"`` when a choice is close to ``word``, else ``""``."""
    names = {str(c).lower(): str(c) for c in choices}
    close = difflib.get_close_matches(str(word).lower(), list(names), n=1, cutoff=0.6)
    return f" (did you mean {quote(names[close[0]])}?)" if close else ""


def fail(path: str, value: Any, expected: str, detail: str = "") -> None:
    """Raise the standard message ``path = value: expected ...``."""
    raise InputError(f"{path} = {show(value)}: expected {expected}{detail}")


def join(path: str, key: str) -> str:
    return f"{path}.{key}" if path else key


def table_label(path: str) -> str:
    return f"[{path}]" if path else "[top level]"


@dataclass
class Context:
    """What validation needs besides the value: the folder relative paths start from."""

    base_dir: Path = field(default_factory=Path.cwd)


# --- value specs ----------------------------------------------------------------------
class Spec:
    """A kind of value: checks and normalises it, and says what it expects."""

    def expected(self, plural: bool = False) -> str:
        raise NotImplementedError

    def matches(self, value: Any) -> bool:
        """True when ``value`` has the right TOML type (used to pick an :class:`AnyOf` branch)."""
        raise NotImplementedError

    def check(self, value: Any, path: str, ctx: Context) -> Any:
        raise NotImplementedError

    def _type_error(self, value, path):
        fail(path, value, self.expected(), f", got {type_name(value)}")


def _is_number(value) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


@dataclass
class Number(Spec):
    """A real number, optionally bounded; ``allow_inf`` accepts ``inf`` and ``"inf"``."""

    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    allow_inf: bool = False
    noun: tuple = ("a number", "numbers")

    def expected(self, plural: bool = False) -> str:
        text = self.noun[1 if plural else 0]
        lo, hi = self.lo, self.hi
        if lo is not None and hi is not None:
            left, right = "(" if self.lo_open else "[", ")" if self.hi_open else "]"
            text += f" in {left}{lo:g}, {hi:g}{right}"
        elif lo is not None:
            text += f" {'>' if self.lo_open else '>='} {lo:g}"
        elif hi is not None:
            text += f" {'<' if self.hi_open else '<='} {hi:g}"
        if self.allow_inf:
            text += ' or inf (also "inf")'
        return text

    def matches(self, value) -> bool:
        return _is_number(value) or (self.allow_inf and isinstance(value, str))

    def check(self, value, path, ctx):
        if self.allow_inf and isinstance(value, str) and value.strip().lower() in (
            "inf", "+inf", "infinity"
        ):
            value = math.inf
        if not _is_number(value):
            self._type_error(value, path)
        if isinstance(value, int) and abs(value) >= 2**1023:  # no float holds it
            fail(path, value, self.expected(), " (too large for a floating-point number)")
        if math.isnan(value) or (math.isinf(value) and not (self.allow_inf and value > 0)):
            fail(path, value, self.expected())
        if self.lo is not None and (value < self.lo or (self.lo_open and value == self.lo)):
            fail(path, value, self.expected())
        if self.hi is not None and not (self.allow_inf and value == math.inf) and (
                value > self.hi or (self.hi_open and value == self.hi)):
            fail(path, value, self.expected())
        return value


#: the largest magnitude of an integer key: below numpy's int64 limit (2^63 - 1), far above any
#: count or index a model can have
INTEGER_MAX = 2**62


@dataclass
class Integer(Number):
    """An integer, optionally bounded (a float such as ``3.0`` is refused: a likely typo)."""

    noun: tuple = ("an integer", "integers")

    def matches(self, value) -> bool:
        return isinstance(value, int) and not isinstance(value, bool)

    def check(self, value, path, ctx):
        if not self.matches(value):
            self._type_error(value, path)
        out = int(super().check(value, path, ctx))
        if abs(out) > INTEGER_MAX:  # numpy's int64 would overflow (an OverflowError)
            fail(path, value, f"{self.expected()} of magnitude at most 2^62 (no count or "
                 "index of a model comes near it)")
        return out


@dataclass
class Text(Spec):
    """A string, optionally one of ``choices`` (a near miss gets a suggestion)."""

    choices: tuple | None = None

    def expected(self, plural: bool = False) -> str:
        if self.choices:
            names = ", ".join(show(c) for c in self.choices)
            return f"strings from {names}" if plural else f"one of {names}"
        return "strings" if plural else "a string"

    def matches(self, value) -> bool:
        return isinstance(value, str)

    def check(self, value, path, ctx):
        if not isinstance(value, str):
            self._type_error(value, path)
        if self.choices and value not in self.choices:
            fail(path, value, self.expected(), suggest(value, self.choices, show))
        return value


@dataclass
class Choice(Spec):
    """One of a few fixed integer values (e.g. a sign: -1 or 1)."""

    values: tuple

    def expected(self, plural: bool = False) -> str:
        return ("integers from " if plural else "one of ") + ", ".join(map(str, self.values))

    def matches(self, value) -> bool:
        return isinstance(value, int) and not isinstance(value, bool)

    def check(self, value, path, ctx):
        if not self.matches(value):
            self._type_error(value, path)
        if value not in self.values:
            fail(path, value, self.expected())
        return value


@dataclass
class Flag(Spec):
    """``true`` or ``false``."""

    def expected(self, plural: bool = False) -> str:
        return "booleans" if plural else "true or false"

    def matches(self, value) -> bool:
        return isinstance(value, bool)

    def check(self, value, path, ctx):
        if not isinstance(value, bool):
            self._type_error(value, path)
        return value


@dataclass
class ListOf(Spec):
    """A list whose items all match ``item``; ``sizes`` restricts its length."""

    item: Spec
    sizes: tuple | None = None
    non_empty: bool = False
    unique: bool = False

    def expected(self, plural: bool = False) -> str:
        if self.sizes:
            n = " or ".join(str(s) for s in self.sizes)
            head = f"lists of {n}" if plural else f"a list of {n}"
        else:
            head = "non-empty lists" if (plural and self.non_empty) else (
                "lists" if plural else ("a non-empty list" if self.non_empty else "a list"))
            head += " of"
        text = f"{head} {self.item.expected(plural=True)}"
        return text + (" (no repeats)" if self.unique else "")

    def matches(self, value) -> bool:
        return isinstance(value, list | tuple)

    def check(self, value, path, ctx):
        if not self.matches(value):
            self._type_error(value, path)
        if (self.sizes and len(value) not in self.sizes) or (self.non_empty and not value):
            fail(path, value, self.expected())
        out = []
        for i, v in enumerate(value):
            if not self.item.matches(v):
                fail(path, value, self.expected(), f"; item {i + 1} is {type_name(v)}")
            out.append(self.item.check(v, f"{path}[{i + 1}]", ctx))
        if self.unique and len({repr(v) for v in out}) != len(out):
            fail(path, value, self.expected())
        return out


def Vector(sizes=(2, 3)) -> ListOf:
    """A list of 2 or 3 finite numbers (a point, a direction, a traction)."""
    return ListOf(Number(), sizes=tuple(sizes))


@dataclass
class FilePath(Spec):
    """A path to an existing file; relative paths start from the case file's folder."""

    def expected(self, plural: bool = False) -> str:
        return "paths of existing files" if plural else "the path of an existing file"

    def matches(self, value) -> bool:
        return isinstance(value, str)

    def check(self, value, path, ctx):
        if not isinstance(value, str) or not value.strip():
            self._type_error(value, path)
        p = Path(value).expanduser()
        p = p if p.is_absolute() else (ctx.base_dir / p)
        try:
            found = p.is_file()
        except OSError as exc:  # e.g. a name too long for the file system
            fail(path, value, self.expected(), f" ({exc.strerror or exc})")
        if not found:
            fail(path, value, self.expected(), f" (no file at {p})")
        return p.resolve()


@dataclass
class AnyOf(Spec):
    """One of several specs, chosen by the TOML type of the value."""

    options: tuple

    def expected(self, plural: bool = False) -> str:
        return " or ".join(o.expected(plural) for o in self.options)

    def matches(self, value) -> bool:
        return any(o.matches(value) for o in self.options)

    def check(self, value, path, ctx):
        for option in self.options:
            if option.matches(value):
                if isinstance(value, list | tuple | Mapping):
                    return option.check(value, path, ctx)  # its message names the item
                try:
                    return option.check(value, path, ctx)
                except InputError:
                    hint = ""
                    if isinstance(option, Text) and option.choices:
                        hint = suggest(value, option.choices, show)
                    fail(path, value, self.expected(), hint)
        self._type_error(value, path)


@dataclass
class Field:
    """One key of a :class:`Table`.

    Attributes
    ----------
    spec : the kind of value.
    doc : one-sentence description (documentation and messages).
    required : the key must be given.
    default : value used when the key is absent (``MISSING``: left out of the output).
    unit : SI unit written in the docs (``""`` for none, ``"-"`` for dimensionless).
    used_by : the analysis types that read the key (None: every one).
    """

    spec: Spec
    doc: str
    required: bool = False
    default: Any = MISSING
    unit: str = ""
    used_by: tuple | None = None
    """The analysis types that read the key (None: every one); given to another, the key is
    named as ignored (:func:`unused_keys`)."""


@dataclass
class Table(Spec):
    """A TOML table with a fixed set of keys; unknown keys are errors (typos).

    ``checks`` are functions ``check(out, path)`` run on the normalised table for rules
    across keys (e.g. "``pressure`` or ``traction``, not both"); they raise with :func:`fail`
    or :class:`InputError`. ``doc`` is a paragraph for the documentation.
    """

    fields: dict
    checks: tuple = ()
    doc: str = ""

    def expected(self, plural: bool = False) -> str:
        return "tables" if plural else "a table"

    def matches(self, value) -> bool:
        return isinstance(value, Mapping)

    def check(self, value, path, ctx):
        if not isinstance(value, Mapping):
            self._type_error(value, path)
        for key in value:
            if key not in self.fields:
                raise InputError(
                    f"unknown key {str(key)!r} in {table_label(path)}; expected one "
                    f"of: {', '.join(self.fields)}{suggest(key, self.fields)}"
                )
        out = {}
        for key, f in self.fields.items():
            if key in value:
                out[key] = f.spec.check(value[key], join(path, key), ctx)
            elif f.required:
                unit = f" [{f.unit}]" if f.unit and f.unit != "-" else ""
                raise InputError(
                    f"missing required key {join(path, key)!r} ({f.doc.rstrip('.')}{unit}: "
                    f"{f.spec.expected()})"
                )
            elif f.default is not MISSING:
                out[key] = f.default
        for rule in self.checks:
            rule(out, path)
        return out


@dataclass
class TableList(Spec):
    """A TOML array of tables (``[[name]]`` blocks), each validated by ``table``."""

    table: Table

    def expected(self, plural: bool = False) -> str:
        return "arrays of tables" if plural else "an array of tables ([[...]] blocks)"

    def matches(self, value) -> bool:
        return isinstance(value, list | tuple)

    def check(self, value, path, ctx):
        if isinstance(value, Mapping):  # [name] written instead of [[name]]: one item,
            return [self.table.check(value, path, ctx)]  # named as written
        if not isinstance(value, list | tuple):
            self._type_error(value, path)
        return [self.table.check(v, f"{path}[{i + 1}]", ctx) for i, v in enumerate(value)]


@dataclass
class Dict(Spec):
    """A table with free key names (e.g. observed points); values match ``value``.

    ``key_ok(key) -> bool`` restricts the key names, described by ``key_doc``.
    """

    value: Spec
    key_ok: Callable[[str], bool] | None = None
    key_doc: str = "names"

    def expected(self, plural: bool = False) -> str:
        return f"{'tables' if plural else 'a table'} of {self.key_doc} = {self.value.expected()}"

    def matches(self, value) -> bool:
        return isinstance(value, Mapping)

    def check(self, value, path, ctx):
        if not isinstance(value, Mapping):
            self._type_error(value, path)
        out = {}
        for key, v in value.items():
            if self.key_ok is not None and not self.key_ok(key):
                raise InputError(f"{path}: key {key!r} is not valid; expected {self.key_doc}")
            out[key] = self.value.check(v, join(path, key), ctx)
        return out


@dataclass
class Variant(Spec):
    """A table whose keys depend on its ``key`` (e.g. ``type``): one :class:`Table` per value.

    ``options`` is a dict ``value -> Table`` or a function returning it (for registries that
    fill up at import time). The selector key is added to each option's fields.
    """

    options: Any
    key: str = "type"
    key_doc: str = "which kind"

    def tables(self) -> dict:
        return dict(self.options() if callable(self.options) else self.options)

    def expected(self, plural: bool = False) -> str:
        return "tables" if plural else "a table"

    def matches(self, value) -> bool:
        return isinstance(value, Mapping)

    def selector(self) -> Field:
        return Field(Text(tuple(self.tables())), self.key_doc, required=True)

    def check(self, value, path, ctx):
        if not isinstance(value, Mapping):
            self._type_error(value, path)
        sel = self.selector()
        if self.key not in value:
            raise InputError(
                f"missing required key {join(path, self.key)!r} ({self.key_doc}: "
                f"{sel.spec.expected()})"
            )
        kind = sel.spec.check(value[self.key], join(path, self.key), ctx)
        table = self.tables()[kind]
        full = Table({self.key: sel, **table.fields}, table.checks, table.doc)
        return full.check(value, path, ctx)


# --- keys an analysis does not read -----------------------------------------------------
def unused_keys(spec: Spec, value: Any, analysis: str, path: str = "") -> list[tuple]:
    """``(key path, value, used_by)`` of every key given in the validated ``value`` of
    ``spec`` that the analysis type ``analysis`` does not read (its :attr:`Field.used_by`
    leaves it out), walking the schema: so a key declared with ``used_by`` is covered
    wherever it sits. A key given its default, or a switch turned off (``false``), changes
    nothing and is not listed."""
    out: list[tuple] = []
    if isinstance(spec, Variant) and isinstance(value, Mapping):
        table = spec.tables().get(value.get(spec.key))
        if table is not None:
            out += unused_keys(table, value, analysis, path)
    elif isinstance(spec, Table) and isinstance(value, Mapping):
        for key, f in spec.fields.items():
            if key not in value:
                continue
            v, sub = value[key], join(path, key)
            if f.used_by is not None and analysis not in f.used_by:
                if not (v is False or (f.default is not MISSING and v == f.default)):
                    out.append((sub, v, f.used_by))
            else:
                out += unused_keys(f.spec, v, analysis, sub)
    elif isinstance(spec, TableList) and isinstance(value, list | tuple):
        for i, item in enumerate(value):
            out += unused_keys(spec.table, item, analysis,
                               f"{path}[{i + 1}]" if len(value) > 1 else path)
    elif isinstance(spec, TableList) and isinstance(value, Mapping):
        out += unused_keys(spec.table, value, analysis, path)
    elif isinstance(spec, Dict) and isinstance(value, Mapping):
        for key, v in value.items():
            out += unused_keys(spec.value, v, analysis, join(path, str(key)))
    elif isinstance(spec, AnyOf):
        for option in spec.options:
            if option.matches(value):
                out += unused_keys(option, value, analysis, path)
                break
    return out


# --- rules across keys of a table (for Table.checks) ---------------------------------
def exactly_one(*keys: str):
    """Rule: exactly one of ``keys`` is given."""

    def rule(out, path):
        given = [k for k in keys if k in out]
        if len(given) != 1:
            names = ", ".join(repr(k) for k in keys)
            got = ", ".join(repr(k) for k in given) or "none"
            raise InputError(f"{table_label(path)}: give exactly one of {names} (got {got})")

    return rule


def requires(key: str, partner: str, *, excludes: str | None = None):
    """Rule: when ``key`` is given, ``partner`` must be given (and ``excludes`` must not)."""

    def rule(out, path):
        if key not in out:
            return
        if partner not in out:
            raise InputError(f"{table_label(path)}: {key!r} needs {partner!r}")
        if excludes is not None and excludes in out:
            raise InputError(f"{table_label(path)}: {key!r} cannot be used with {excludes!r}")

    return rule


def non_zero(*keys: str):
    """Rule: the vectors ``keys`` (when given) are not all zeros."""

    def rule(out, path):
        for k in keys:
            if k in out and not any(out[k]):
                fail(join(path, k), out[k], "a non-zero vector")

    return rule


def increasing(lo: str, hi: str, unit: str = ""):
    """Rule: ``out[lo] < out[hi]`` when both are given (e.g. a frequency band)."""

    def rule(out, path):
        if lo in out and hi in out and not out[lo] < out[hi]:
            fail(join(path, hi), out[hi], f"a value above {lo} = {show(out[lo])}"
                 + (f" {unit}" if unit else ""))

    return rule


# --- documentation --------------------------------------------------------------------
def _md(text: str) -> str:
    return text.replace("|", "\\|")


def render_table(table: Table, heading: str) -> str:
    """Markdown for one table: its paragraph, then a row per key."""
    lines = [heading, ""]
    if table.doc:
        lines += [table.doc, ""]
    lines += ["| key | value | unit | default | description |", "|---|---|---|---|---|"]
    for key, f in table.fields.items():
        if f.required:
            default = "**required**"
        elif f.default is MISSING or f.default is None:
            default = "-"
        else:
            default = f"`{show(f.default)}`"
        unit = f.unit or ""
        doc = f.doc + (f" (read by {', '.join(f.used_by)} only)" if f.used_by else "")
        lines.append(
            f"| `{key}` | {_md(f.spec.expected())} | {_md(unit)} | {default} | {_md(doc)} |"
        )
    return "\n".join(lines) + "\n"
