"""Direct tests of the declarative schema (fretwear.io.schema).

Reference: the schema's own contract, written out by hand for each kind of value: what is
accepted, the normalised value it returns, and the one-line message (key path, value as
written in TOML, what is expected) for what is refused.
"""

import math

import pytest

from fretwear.errors import InputError
from fretwear.io.schema import (
    MISSING,
    AnyOf,
    Context,
    Dict,
    Field,
    FilePath,
    Flag,
    Integer,
    ListOf,
    Number,
    Table,
    TableList,
    Text,
    Variant,
    exactly_one,
    increasing,
    render_table,
    show,
    suggest,
)

CTX = Context()


def message(spec, value, path="a.b"):
    with pytest.raises(InputError) as exc:
        spec.check(value, path, CTX)
    text = str(exc.value)
    assert "\n" not in text  # one line
    return text


def test_show_writes_values_as_toml():
    assert show(True) == "true"
    assert show("x") == '"x"'
    assert show(math.inf) == "inf"
    assert show([1, 2.5, "a"]) == '[1, 2.5, "a"]'
    assert show("y" * 100, limit=10) == '"yyyyyy...'


@pytest.mark.parametrize("spec,value,expected", [
    (Number(), 2.5, 2.5),
    (Number(), 2, 2),  # an integer stays an integer (TOML's own type)
    (Number(lo=0), 0.0, 0.0),
    (Number(allow_inf=True), "inf", math.inf),
    (Integer(lo=1), 3, 3),
])
def test_numbers_accepted_and_normalised(spec, value, expected):
    out = spec.check(value, "k", CTX)
    assert out == expected and type(out) is type(expected)


def test_number_bounds_and_types_name_the_key():
    assert message(Number(lo=0, lo_open=True), 0.0) == "a.b = 0.0: expected a number > 0"
    assert message(Number(lo=-1, hi=0.5, lo_open=True, hi_open=True), 0.5) == (
        "a.b = 0.5: expected a number in (-1, 0.5)")
    assert message(Number(), "x").startswith('a.b = "x": expected a number')
    assert message(Number(), True).endswith("got a boolean")  # TOML true is not 1
    assert "a.b = nan" in message(Number(), math.nan)
    assert "a.b = 2.5" in message(Integer(), 2.5)
    huge = 10**400  # TOML integers are unbounded in Python; no float can hold this one
    assert message(Number(), huge).endswith("(too large for a floating-point number)")
    assert message(Integer(lo=1), -huge).endswith("(too large for a floating-point number)")


def test_text_choices_suggest_the_nearest():
    spec = Text(("powell", "newton", "hybr"))
    assert spec.check("newton", "k", CTX) == "newton"
    msg = message(spec, "nweton", "analysis.solver")
    assert msg.startswith('analysis.solver = "nweton": expected one of')
    assert msg.endswith('(did you mean "newton"?)')
    assert suggest("zzz", ("powell",)) == ""


def test_flag_and_lists():
    assert Flag().check(True, "k", CTX) is True
    assert "a.b = 1" in message(Flag(), 1)
    spec = ListOf(Integer(lo=1), non_empty=True, unique=True)
    assert spec.check([3, 1], "k", CTX) == [3, 1]
    assert "item 2" in message(spec, [1, "x"])
    message(spec, [])  # non-empty
    message(spec, [2, 2])  # unique


def test_file_path_resolves_against_the_case_folder(tmp_path):
    (tmp_path / "K.mtx").write_text("x")
    ctx = Context(tmp_path)
    assert FilePath().check("K.mtx", "k", ctx) == tmp_path / "K.mtx"
    with pytest.raises(InputError, match="no file at"):
        FilePath().check("missing.mtx", "k", ctx)


def test_any_of_picks_the_branch_of_the_value_type():
    spec = AnyOf((Integer(lo=1), ListOf(Integer(lo=1))))
    assert spec.check(7, "k", CTX) == 7
    assert spec.check([1, 3], "k", CTX) == [1, 3]
    message(spec, "seven")


def test_table_defaults_required_unknown_keys():
    t = Table({"a": Field(Number(), "a number", required=True),
               "b": Field(Integer(), "an integer", default=2),
               "c": Field(Text(), "optional, no default", default=MISSING)})
    assert t.check({"a": 1}, "sec", CTX) == {"a": 1.0, "b": 2}
    with pytest.raises(InputError, match="missing required key 'sec.a'"):
        t.check({}, "sec", CTX)
    with pytest.raises(InputError, match=r"unknown key 'bb' in \[sec\].*did you mean 'b'"):
        t.check({"a": 1, "bb": 3}, "sec", CTX)


def test_rules_across_keys():
    t = Table({"x": Field(Number(), "x"), "y": Field(Number(), "y"),
               "f_min": Field(Number(), "lo"), "f_max": Field(Number(), "hi")},
              (exactly_one("x", "y"), increasing("f_min", "f_max", "Hz")))
    assert t.check({"x": 1}, "s", CTX)["x"] == 1.0
    with pytest.raises(InputError, match="give exactly one of 'x', 'y'"):
        t.check({"x": 1, "y": 2}, "s", CTX)
    with pytest.raises(InputError, match=r"s.f_max = 1.0: expected a value above f_min = 2.0 Hz"):
        t.check({"x": 1, "f_min": 2.0, "f_max": 1.0}, "s", CTX)


def test_table_lists_number_items_from_one():
    spec = TableList(Table({"v": Field(Number(lo=0), "v", required=True)}))
    with pytest.raises(InputError, match=r"^loads\[2\]\.v = -1"):
        spec.check([{"v": 1}, {"v": -1}], "loads", CTX)


def test_dict_and_variant():
    d = Dict(Integer(lo=0), key_doc="point names")
    assert d.check({"p": 3}, "observed", CTX) == {"p": 3}
    v = Variant({"box": Table({"n": Field(Integer(lo=1), "n", default=1)})}, key_doc="kind")
    assert v.check({"type": "box"}, "model", CTX) == {"type": "box", "n": 1}
    with pytest.raises(InputError, match="missing required key 'model.type'"):
        v.check({}, "model", CTX)
    with pytest.raises(InputError, match=r'model.type = "bx".*did you mean "box"'):
        v.check({"type": "bx"}, "model", CTX)


def test_render_table_documents_every_key():
    t = Table({"E": Field(Number(lo=0, lo_open=True), "Young's modulus", required=True,
                          unit="Pa"),
               "n": Field(Integer(), "count | pipes escaped", default=3)}, doc="A table.")
    md = render_table(t, "## [material]")
    assert md.startswith("## [material]\n\nA table.\n")
    assert "| `E` | a number > 0 | Pa | **required** | Young's modulus |" in md
    assert "| `n` | an integer |  | `3` | count \\| pipes escaped |" in md


def test_unused_keys_walks_every_kind_of_table():
    """A key declared for some analyses (``used_by``) is named wherever it sits (a table, an
    array of tables numbered as the messages number them, a free-key table, a variant), with
    its path and value; its default and a switch turned off are not named (they change
    nothing); under an analysis that reads it nothing is named. Reference: the hand-written
    case below."""
    from fretwear.io.schema import Dict, Field, Flag, Number, Table, TableList, Variant, unused_keys

    k = Field(Number(), "a coefficient", default=0.0, used_by=("wear",))
    s = Field(Flag(), "a switch", default=False, used_by=("wear",))
    inner = Table({"k": k, "s": s, "x": Field(Number(), "x")})
    top = Table({"one": Field(inner, "one"), "many": Field(TableList(inner), "many"),
                 "free": Field(Dict(inner), "free"),
                 "v": Field(Variant({"a": inner}), "variant")})
    case = {"one": {"k": 1.0, "x": 2.0}, "many": [{"k": 0.0}, {"k": 3.0, "s": True}],
            "free": {"body": {"s": False, "k": 4.0}}, "v": {"type": "a", "k": 5.0}}
    found = [(p, v) for p, v, _ in unused_keys(top, case, "periodic")]
    assert found == [("one.k", 1.0), ("many[2].k", 3.0), ("many[2].s", True),
                     ("free.body.k", 4.0), ("v.k", 5.0)]
    assert unused_keys(top, case, "wear") == []
