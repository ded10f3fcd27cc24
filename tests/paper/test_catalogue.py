"""The runs of the reproduction (fretwear.paper.catalogue): values written into case files
and the edited case text of every run.

References: Python's own TOML parser (tomllib, an independent implementation of the format)
reads back what the catalogue writes, and the case-file validation of ``fretwear run``
(load_case) reads back every run's edits.
"""

import tomllib

import pytest

from fretwear.analyses.run import load_case
from fretwear.errors import InputError
from fretwear.paper.catalogue import RUNS, edit_case_text, run_case_text, toml_value


@pytest.mark.parametrize("value", [3, 2e8, 1e-12, float("inf"), True, False, "static",
                                   'a "quoted" \\ path', ["sliding", "stuck"], [0.1, 0.005]])
def test_toml_values_read_back(value):
    """Each value written by toml_value is read back equal by Python's TOML parser (an
    independent implementation of the format)."""
    assert tomllib.loads(f"k = {toml_value(value)}")["k"] == value


def test_edit_replaces_and_appends_keys_of_one_table_only():
    text = ("title = \"t\"\n[model]\nnx = 30  # comment\nny = 4\n\n[analysis]\n"
            "type = \"wear\"\nharmonics = 7  # paper\nnx = 1\n")
    out = edit_case_text(text, "analysis", {"harmonics": 3, "max_cycles": 2e3})
    parsed = tomllib.loads(out)
    assert parsed["analysis"] == {"type": "wear", "harmonics": 3, "nx": 1, "max_cycles": 2e3}
    assert parsed["model"] == {"nx": 30, "ny": 4}
    out = edit_case_text(out, "model", {"nx": 100})
    assert tomllib.loads(out)["model"]["nx"] == 100
    assert tomllib.loads(out)["analysis"]["nx"] == 1
    with pytest.raises(InputError, match=r"no table \[damping\]"):
        edit_case_text(text, "damping", {"loss_factor": 0.0})


@pytest.mark.parametrize("quick", [False, True], ids=["full", "quick"])
def test_every_run_is_a_valid_case_with_its_edits(tmp_path, quick):
    """Every run's case text validates and carries its edits (read back by load_case)."""
    for run in RUNS:
        path = tmp_path / f"{run.key}.toml"
        path.write_text(run_case_text(run, quick))
        case = load_case(path)
        edits = {**run.analysis, **(run.quick if quick else {})}
        for k, v in edits.items():
            assert case.analysis[k] == v, (run.key, k)
        for k, v in {**run.model, **(run.quick_model if quick else {})}.items():
            assert case.model["model"][k] == v, (run.key, k)


def test_run_keys_are_unique_and_every_example_is_shipped():
    """A run's key is its folder in the work directory: two runs of one key would overwrite
    each other. Each run's example exists among the shipped case files (the package's own
    examples folder, listed here directly)."""
    from fretwear.examples import EXAMPLES_DIR

    keys = [r.key for r in RUNS]
    assert len(set(keys)) == len(keys)
    shipped = {p.stem for p in EXAMPLES_DIR.glob("*.toml")}
    assert {r.example for r in RUNS} <= shipped


def test_floats_are_written_to_their_last_digit():
    """A case file must hold the number the run used, not a rounded one: tomllib reads back
    the same double (exact equality) for values with 17 significant digits."""
    import math

    for v in (math.pi, 0.1 + 0.2, -1.0000000000000002, 6.02214076e23, 5e-324):
        assert tomllib.loads(f"k = {toml_value(v)}")["k"] == v


def test_toml_value_refuses_what_toml_cannot_hold():
    """None and dictionaries have no single-line TOML value here: one InputError."""
    for bad in (None, {"a": 1}):
        with pytest.raises(InputError, match="cannot write .* into a case file"):
            toml_value(bad)
