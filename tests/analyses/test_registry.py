"""The analysis registry (fretwear.analyses.registry): lookup by name, its messages, the refusal
of a second registration under a taken name, and the order of the tables.

Reference: the registry's contract written out here (the modules of ANALYSIS_MODULES in their
order, each registering its names; one clear InputError line for an unknown type).
"""

import pytest

from fretwear.analyses import registry
from fretwear.errors import InputError
from fretwear.io.schema import Field, Integer

EXPECTED = ["modes", "frf", "periodic", "sweep", "transient", "incremental-wear", "wear"]


@pytest.fixture
def scratch():
    """Names registered by a test are removed after it."""
    before = dict(registry._REGISTRY)
    yield
    registry._REGISTRY.clear()
    registry._REGISTRY.update(before)


def test_every_analysis_is_listed_in_module_order():
    assert registry.available() == EXPECTED
    assert list(registry.analysis_tables()) == EXPECTED
    for name in EXPECTED:
        a = registry.get(name)
        assert a.name == name and callable(a.run)
        assert a.run.__module__ in registry.ANALYSIS_MODULES
    assert registry.get("wear").files  # the checkpoint file it keeps


def test_unknown_type_names_the_available_ones():
    with pytest.raises(InputError) as e:
        registry.get("modal")
    assert str(e.value) == ("analysis.type = 'modal' is not available; expected one of: "
                            + ", ".join(EXPECTED))


def run_a(model, analysis, case, outdir, progress):
    raise AssertionError("not run here")


def run_b(model, analysis, case, outdir, progress):
    raise AssertionError("not run here")


def test_register_and_get(scratch):
    registry.register("scratch", {"n": Field(Integer(lo=1), "a count", default=2)}, run_a,
                      doc="A test analysis.")
    a = registry.get("scratch")
    assert a.run is run_a and "n" in a.schema.fields and a.files == ()
    assert "scratch" in registry.analysis_tables()
    registry.register("scratch", a.schema, run_a)  # the same function again: accepted


def test_a_taken_name_is_refused(scratch):
    registry.register("scratch", {}, run_a)
    with pytest.raises(ValueError, match="'scratch' is already registered by"):
        registry.register("scratch", {}, run_b)
    assert registry.get("scratch").run is run_a


def test_type_is_not_a_schema_key(scratch):
    with pytest.raises(ValueError, match="'type' is added by the registry"):
        registry.register("scratch", {"type": Field(Integer(), "no")}, run_a)
