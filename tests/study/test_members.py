"""The members of a study (fretwear.study.members): grids, seeded samples, seeded
perturbations and chunks of a sweep expanded into complete case files, and the dotted key
paths that address a case.

References: what each kind of study means, computed independently here (itertools.product
for a grid, the strata of a Latin hypercube counted by hand, sample moments, the base sweep's
own frequency grid), and Python's TOML parser reading back each member's case text.
"""

from __future__ import annotations

import copy
import itertools
import tomllib

import numpy as np
import pytest
from helpers.studies import SWEEP, base_case, study_file

from fretwear.errors import InputError
from fretwear.study.members import Member, expand, get_key, set_key
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


CASE = {"contact": {"mu": 0.3},
        "loads": [{"name": "P", "pressure": 1e4}, {"name": "Q", "pressure": 2e4},
                  {"name": "T", "traction": [0.0, 1e4, 0.0]}]}


def test_key_paths_address_tables_and_blocks_by_name_or_number():
    """``loads.Q.pressure`` and ``loads[2].pressure`` are the same value (blocks numbered
    from 1, as the study files document); a missing key is None; set_key creates missing
    tables and changes only the addressed value (the rest compared with a deep copy)."""
    raw = copy.deepcopy(CASE)
    assert get_key(raw, "loads.Q.pressure") == get_key(raw, "loads[2].pressure") == 2e4
    assert get_key(raw, "contact.mu") == 0.3 and get_key(raw, "contact.gap") is None
    set_key(raw, "loads[1].pressure", 5.0)
    set_key(raw, "damping.loss_factor", 1e-3)
    expected = copy.deepcopy(CASE)
    expected["loads"][0]["pressure"] = 5.0
    expected["damping"] = {"loss_factor": 1e-3}
    assert raw == expected


def test_a_vector_and_one_of_its_components_are_keys():
    """``loads.T.traction`` is the whole vector; ``loads.T.traction.2`` its second
    component (counted from 1, as blocks are); setting a component changes only it (the rest
    compared with a deep copy)."""
    raw = copy.deepcopy(CASE)
    assert get_key(raw, "loads.T.traction") == [0.0, 1e4, 0.0]
    assert get_key(raw, "loads.T.traction.2") == 1e4
    set_key(raw, "loads.T.traction.3", -5.0)
    expected = copy.deepcopy(CASE)
    expected["loads"][2]["traction"] = [0.0, 1e4, -5.0]
    assert raw == expected


def test_tied_keys_vary_together_as_one_axis_of_the_grid(tmp_path):
    """``[[grid.tied]]``: the i-th values of the tied keys go to the same member, and the
    group is one axis of the combinations with the other grid keys (itertools.product over
    the axes, the tied pairs zipped); a vector value is set whole."""
    base_case(tmp_path)
    path = study_file(tmp_path, '[grid]\ncontact.mu = [0.1, 0.2]\n[[grid.tied]]\n'
                      '"loads[2].pressure" = [1e3, 2e3]\n"analysis.harmonics" = [1, 3]\n')
    members = _members(path)
    got = [(_case(m)["contact"]["mu"], _case(m)["loads"][1]["pressure"],
            _case(m)["analysis"]["harmonics"]) for m in members]
    assert got == [(mu, p, h) for mu, (p, h) in itertools.product(
        [0.1, 0.2], zip([1e3, 2e3], [1, 3], strict=True))]
    path = study_file(tmp_path, '[grid]\n"loads[1].pressure" = [1.0]\n')
    assert len(_members(path)) == 1


@pytest.mark.parametrize("key, words", [
    ("loads[4].pressure", "has 3 [[loads]] blocks; expected a number from 1 to 3"),
    ("loads.X.pressure", "no [[loads]] block named 'X' (names: P, Q, T)"),
    ("loads.T.traction.4", "is a vector of 3 components; expected loads.T.traction (the whole "
     "vector) or loads.T.traction.N, N a component number from 1 to 3"),
    ("loads.T.traction.x", "component number from 1 to 3"),
    ("loads.pressure", "is an array of tables; name a block and a key"),
    ("contact.mu.value", "contact.mu = 0.3 is a value, not a table"),
])
def test_bad_key_paths_are_one_error_naming_the_key(key, words):
    with pytest.raises(InputError) as err:
        get_key(CASE, key)
    assert str(err.value).startswith(f"{key}: ") and words in str(err.value)


def test_member_folder_and_description():
    """Folders sort in member order up to 9999 members (four digits); the description lists
    the varied values, "base" for none."""
    assert Member(7, {}).folder_name == "member-0007"
    assert Member(0, {}).describe() == "base"
    assert Member(1, {"contact.mu": 0.1, "loads.Q.pressure": 2e4}).describe() == \
        "contact.mu = 0.1, loads.Q.pressure = 20000"
