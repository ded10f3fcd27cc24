"""The analysis registry (fretwear.analyses.registry): lookup by name, its messages, the order of
the tables, the refusal of a name defined twice, and that it lists exactly the analyses the
analysis modules define.

Reference: the registry's contract written out here (the nine analyses in the order of
docs/case-files.md; one clear InputError line for an unknown type), and, independently of the
registry's own list, the Analysis objects found by walking the modules of fretwear.analyses.
"""

import importlib
import pkgutil

import pytest

import fretwear.analyses
from fretwear.analyses import registry
from fretwear.analyses.base import Analysis
from fretwear.errors import InputError
from fretwear.io.schema import Field, Integer, Table

EXPECTED = ["modes", "frf", "cyclic-modes", "periodic", "sweep", "nonlinear-modes", "transient",
            "incremental-wear", "wear", "worn-state"]


def test_every_analysis_is_listed_in_order():
    assert registry.available() == EXPECTED
    assert list(registry.analysis_tables()) == EXPECTED
    assert [a.name for a in registry.ANALYSES] == EXPECTED
    for name in EXPECTED:
        a = registry.get(name)
        assert a.name == name and callable(a.run)
        assert a.run.__module__.startswith("fretwear.analyses.")
    assert registry.get("wear").files  # the checkpoint file it keeps


def defined_by_modules() -> dict[str, Analysis]:
    """Every Analysis a module of fretwear.analyses defines (its run function is its own),
    found by importing each module: what the registry must list, no more, no less."""
    found = {}
    for info in pkgutil.iter_modules(fretwear.analyses.__path__):
        module = importlib.import_module(f"fretwear.analyses.{info.name}")
        for value in vars(module).values():
            if isinstance(value, Analysis) and value.run.__module__ == module.__name__:
                assert value.name not in found or found[value.name] is value, value.name
                found[value.name] = value
    return found


def test_the_registry_lists_exactly_what_the_modules_define():
    found = defined_by_modules()
    assert set(found) == set(EXPECTED)
    for name, a in found.items():
        assert registry.get(name) is a, name


def test_unknown_type_names_the_available_ones():
    with pytest.raises(InputError) as e:
        registry.get("modal")
    assert str(e.value) == ("analysis.type = 'modal' is not available; expected one of: "
                            + ", ".join(EXPECTED))


def run_a(model, analysis, case, context):
    raise AssertionError("not run here")


def run_b(model, analysis, case, context):
    raise AssertionError("not run here")


def test_define_and_look_up():
    a = Analysis.define("scratch", {"n": Field(Integer(lo=1), "a count", default=2)}, run_a,
                        doc="A test analysis.", files=("state.npz",))
    assert a.run is run_a and "n" in a.schema.fields and a.files == ("state.npz",)
    assert a.schema.doc == "A test analysis." and not a.preload_check
    assert Analysis.define("scratch", a.schema, run_a).schema is a.schema  # a Table as is
    table = registry.by_name([registry.get("modes"), a])
    assert list(table) == ["modes", "scratch"] and table["scratch"] is a
    with pytest.raises(TypeError):
        table["other"] = a  # read-only


def test_a_name_defined_twice_is_refused():
    a = Analysis.define("scratch", {}, run_a)
    b = Analysis.define("scratch", {}, run_b)
    with pytest.raises(ValueError, match=r"'scratch' is defined twice: by \S*\.run_a and "
                                         r"by \S*\.run_b"):
        registry.by_name([a, b])
    with pytest.raises(ValueError, match="'periodic' is defined twice"):
        registry.by_name([*registry.ANALYSES, Analysis.define("periodic", {}, run_a)])


def test_type_is_not_a_schema_key():
    with pytest.raises(ValueError, match="'type' is added by the registry"):
        Analysis.define("scratch", {"type": Field(Integer(), "no")}, run_a)
    with pytest.raises(ValueError, match="'type' is added by the registry"):
        Analysis("scratch", Table({"type": Field(Integer(), "no")}), run_a)


def test_keys_read_by_some_analyses_name_registered_ones():
    """Every key of the case-file schema declared for some analyses (``Field.used_by``, what
    the pass naming ignored keys reads) names registered analyses only: a misspelt type
    would make the key look ignored everywhere. Walks every table of every model kind."""
    from fretwear.analyses.registry import analysis_tables, available
    from fretwear.io import case as case_files
    from fretwear.io.schema import AnyOf, Dict, ListOf, Table, TableList, Variant

    seen, declared = set(), []

    def walk(spec):
        if id(spec) in seen:
            return
        seen.add(id(spec))
        if isinstance(spec, Variant):
            for t in spec.tables().values():
                walk(t)
        elif isinstance(spec, Table):
            for f in spec.fields.values():
                if f.used_by is not None:
                    declared.append(f.used_by)
                walk(f.spec)
        elif isinstance(spec, TableList):
            walk(spec.table)
        elif isinstance(spec, Dict | ListOf):
            walk(spec.value if isinstance(spec, Dict) else spec.item)
        elif isinstance(spec, AnyOf):
            for o in spec.options:
                walk(o)

    for kind in ("mesh", "matrices", "fe"):
        walk(case_files._case_table(kind, analysis_tables()))
    assert declared  # the wear coefficients and output switches at least
    assert {a for used in declared for a in used} <= set(available())
