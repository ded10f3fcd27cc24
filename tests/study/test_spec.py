"""Study files: validation (one line naming the study file and the key) and the expansion
into members (grids, seeded samples, seeded perturbations, chunks of a sweep), compared with
what each kind means, computed independently here."""

from __future__ import annotations

import itertools
import tomllib

import numpy as np
import pytest
from helpers.studies import SWEEP, base_case, study_file

from fretwear import cli
from fretwear.study.members import expand, get_key
from fretwear.study.spec import read_study


def _members(path):
    return expand(read_study(path))


def _case(member) -> dict:
    return tomllib.loads(member.text)


def test_grid_is_every_combination_set_in_the_member_cases(tmp_path):
    base_case(tmp_path)
    path = study_file(tmp_path, '[set]\nanalysis.harmonics = 2\n[grid]\ncontact.mu = [0.1, 0.2]\n'
                      '"loads[2].pressure" = [1e3, 2e3, 3e3]\n')
    members = _members(path)
    assert len(members) == 6
    got = [(_case(m)["contact"]["mu"], _case(m)["loads"][1]["pressure"]) for m in members]
    assert got == list(itertools.product([0.1, 0.2], [1e3, 2e3, 3e3]))
    for m in members:
        case = _case(m)
        assert case["analysis"]["harmonics"] == 2  # [set] applies to every member
        assert "directory" not in case.get("output", {})
        assert case["loads"][0]["pressure"] == 1e4  # the other load is untouched


def test_block_by_name_and_file_paths_made_absolute(tmp_path):
    """A [[loads]] block named in the path; a mesh file named relative to the base case
    becomes absolute in the member case (which lives in another folder)."""
    base_case(tmp_path)
    members = _members(study_file(tmp_path, "[grid]\nloads.Q.pressure = [5.0]\n"))
    assert _case(members[0])["loads"][1]["pressure"] == 5.0


def test_samples_are_seeded_and_follow_their_distributions(tmp_path):
    base_case(tmp_path)
    body = ('[samples]\nn = 40\nseed = 7\nmethod = "latin_hypercube"\n[samples.vary]\n'
            'contact.mu = {distribution = "uniform", low = 0.1, high = 0.5}\n'
            'damping.loss_factor = {distribution = "loguniform", low = 1e-4, high = 1e-2}\n')
    a = _members(study_file(tmp_path, body))
    b = _members(study_file(tmp_path, body, name="again.toml"))
    mu = np.array([m.values["contact.mu"] for m in a])
    eta = np.array([m.values["damping.loss_factor"] for m in a])
    assert [m.values for m in a] == [m.values for m in b]  # same seed, same samples
    # Latin hypercube: exactly one sample in each of the n equal strata of each key
    # (the definition of the design, counted here independently of scipy)
    assert np.array_equal(np.sort(np.floor((mu - 0.1) / 0.4 * 40)), np.arange(40))
    assert np.array_equal(np.sort(np.floor(np.log(eta / 1e-4) / np.log(100) * 40)),
                          np.arange(40))
    assert all(_case(m)["contact"]["mu"] == m.values["contact.mu"] for m in a)


def test_normal_samples_have_the_stated_moments(tmp_path):
    base_case(tmp_path)
    body = ('[samples]\nn = 500\nseed = 3\n[samples.vary]\n'
            'contact.mu = {distribution = "normal", mean = 0.3, std = 0.01}\n')
    mu = np.array([m.values["contact.mu"] for m in _members(study_file(tmp_path, body))])
    # mean within 4 standard errors (0.01 / sqrt(500)), std within 10 % (3 of its standard
    # errors, 1 / sqrt(2 x 500) = 3.2 %)
    assert abs(mu.mean() - 0.3) < 4 * 0.01 / np.sqrt(500)
    assert abs(mu.std() / 0.01 - 1) < 0.1


def test_ensemble_member_zero_is_the_base_and_perturbations_are_seeded(tmp_path):
    base_case(tmp_path)
    body = ('[ensemble]\nmembers = 5\nseed = 11\n[ensemble.perturb]\n'
            'contact.mu = {relative = 1e-6}\ncontact.gap = {absolute = 1e-9, '
            'distribution = "uniform"}\n')
    members = _members(study_file(tmp_path, body))
    assert members[0].values == {}
    assert _case(members[0])["contact"]["mu"] == 0.3
    mu = np.array([m.values["contact.mu"] for m in members[1:]])
    gap = np.array([m.values["contact.gap"] for m in members[1:]])
    assert np.all(mu != 0.3) and np.all(np.abs(mu / 0.3 - 1) < 1e-5)  # 10 sigma
    assert np.all(np.abs(gap) <= 1e-9) and np.all(gap != 0.0)  # uniform in [-1e-9, 1e-9]
    # member i's draws depend on (seed, i) only: a larger ensemble keeps the first members
    more = _members(study_file(tmp_path, body.replace("members = 5", "members = 8"),
                               name="more.toml"))
    assert [m.values for m in more[:5]] == [m.values for m in members]


def test_split_chunks_cover_the_band_and_share_their_ends(tmp_path):
    base_case(tmp_path, SWEEP.replace("n_points = 7", "n_points = 11"))
    members = _members(study_file(tmp_path, "[split]\nchunks = 3\n"))
    full = np.linspace(6e3, 8e3, 11)  # the base sweep's own grid
    freqs = [np.linspace(_case(m)["analysis"]["f_min"], _case(m)["analysis"]["f_max"],
                         _case(m)["analysis"]["n_points"]) for m in members]
    for left, right in itertools.pairwise(freqs):
        assert left[-1] == right[0]
    joined = np.concatenate([freqs[0]] + [f[1:] for f in freqs[1:]])
    np.testing.assert_allclose(joined, full, rtol=1e-14)  # linspace rounding only


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
