"""Study files: validation (one line naming the study file and the key), through the command
line, and the shipped study files. The expansion into members is checked in
test_members.py."""

from __future__ import annotations

import tomllib

import pytest
from helpers.studies import base_case, study_file

from fretwear import cli
from fretwear.study.members import expand, get_key
from fretwear.study.spec import read_study


def _members(path):
    return expand(read_study(path))


def _case(member) -> dict:
    return tomllib.loads(member.text)


@pytest.mark.parametrize("body, words", [
    ("[grid]\ncontact.muu = [0.1]\n", ["study.toml", "member 0", "'muu'", "[contact]"]),
    ("[grid]\ncontact.mu = [0.1, -1.0]\n", ["study.toml", "member 1", "contact.mu = -1.0"]),
    ("[grid]\nloads.X.pressure = [1.0]\n", ["study.toml", "loads.X.pressure", "'X'", "P, Q"]),
    ("[grid]\ncontact.mu = []\n", ["study.toml", "grid.contact.mu", "non-empty"]),
    ("[grid]\nc = [1]\n[samples]\nn = 2\nseed = 1\n", ["study.toml", "exactly one"]),
    ("[samples]\nn = 2\nseed = 1\n[samples.vary]\ncontact.mu = {distribution = \"normal\", "
     "low = 0, high = 1}\n", ["study.toml", "samples.vary.contact.mu", "mean and std"]),
    ("[ensemble]\nmembers = 2\nseed = 1\n[ensemble.perturb]\ncontact.mu = {relative = 0.1, "
     "absolute = 1.0}\n", ["study.toml", "ensemble.perturb.contact.mu", "exactly one"]),
    ("[set]\nanalysis.harmonics = 0\n[grid]\ncontact.mu = [0.1]\n",
     ["study.toml", "[set]", "analysis.harmonics = 0"]),
    ("[split]\nchunks = 2\n", ["study.toml", "sweep", "periodic"]),
    ("[grid\n", ["study.toml", "invalid TOML"]),
    ("[grid]\n[[grid.tied]]\ncontact.mu = [0.1, 0.2]\n\"loads[1].pressure\" = [1.0]\n",
     ["study.toml", "[[grid.tied]] block 1", "differ in length", "contact.mu: 2"]),
    ("[grid]\ncontact.mu = [0.1]\n[[grid.tied]]\ncontact.mu = [0.1]\n",
     ["study.toml", "contact.mu varied twice"]),
    ("[grid]\ncontact.mu = [[0.1, 'a']]\n", ["study.toml", "grid.contact.mu", "vectors"]),
    ("[grid]\n\"loads[1].pressure.2\" = [1.0]\n", ["study.toml", "member 0",
                                                    "is a value, not a table"]),
])
def test_malformed_study_gets_one_line_and_status_2(tmp_path, capsys, body, words):
    base_case(tmp_path)
    path = study_file(tmp_path, body)
    assert cli.main(["study", str(path), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("error: ") and "Traceback" not in err, err
    for w in words:
        assert w in err, (w, err)


@pytest.mark.parametrize("address, words", [
    ("foo", ["scheduler = 'foo'", "missing port", "tcp://host:8786"]),
    ("tcp://host", ["scheduler = 'tcp://host'", "missing port"]),
    ("http://host:8786", ["scheduler = 'http://host:8786'", "unknown protocol 'http'"]),
])
def test_malformed_scheduler_address_gets_one_line_and_writes_nothing(tmp_path, capsys,
                                                                      address, words):
    """A scheduler address Dask cannot parse is refused before any connection is tried (no
    30 s timeout) and before the output folder is made."""
    base_case(tmp_path)
    path = study_file(tmp_path, "[grid]\ncontact.mu = [0.1]\n")
    out = tmp_path / "out"
    assert cli.main(["study", str(path), "-o", str(out), "--scheduler", address,
                     "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("error: ") and "Traceback" not in err, err
    for w in words:
        assert w in err, (w, err)
    assert not out.exists()


def test_missing_base_and_missing_study(tmp_path, capsys):
    path = study_file(tmp_path, "[grid]\ncontact.mu = [0.1]\n", base="nowhere.toml")
    assert cli.main(["study", str(path)]) == 2
    assert "base = \"nowhere.toml\"" in capsys.readouterr().err
    assert cli.main(["study", str(tmp_path / "none.toml")]) == 2
    assert "does not exist" in capsys.readouterr().err


def test_shipped_studies_expand(capsys):
    """The shipped study files are valid and expand to the members their comments state."""
    assert cli.main(["study", "--list"]) == 0
    names = capsys.readouterr().out
    assert "salles2011-79khz-ensemble" in names and "salles2011-frf-mu-load" in names
    from fretwear.study.run import resolve_study

    ens = _members(resolve_study("salles2011-79khz-ensemble"))
    assert len(ens) == 16 and all(_case(m)["analysis"]["max_cycles"] == 5e8 for m in ens)
    frf = _members(resolve_study("salles2011-frf-mu-load"))
    assert len(frf) == 9 and len({(_case(m)["contact"]["mu"],
                                   get_key(_case(m), "loads.Q.pressure")) for m in frf}) == 9
