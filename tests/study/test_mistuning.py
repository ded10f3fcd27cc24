"""The amplification factor of a study over mistuning patterns (fretwear.study.mistuning).

References: members' results files built here with known amplitudes (the blade response is
recomputed by its formula, sqrt(sum_c a_c^2), and the maxima by hand); the members of an
ensemble over ``cyclic.mistuning.young`` drawn by fretwear.study.members (the study machinery
perturbs each of the N factors).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import xarray as xr
from helpers.cyclic import write_sector_case

from fretwear.io.case import read_toml
from fretwear.study.aggregate import aggregate
from fretwear.study.members import Member, expand
from fretwear.study.mistuning import blade_response
from fretwear.study.run import _summary
from fretwear.study.runner import RESULTS_FILE, MemberRecord
from fretwear.study.spec import read_study

STUDY = SimpleNamespace(title="t", kind="ensemble", text="", base="base.toml")
N = 4


def sweep_member(scale, young):
    """A sweep of 3 frequencies on a disk of N sectors: point ``tip@j`` has, at harmonic 1,
    the amplitudes (3 a, 4 a) with a = scale_j x (1, 2, 1) over the frequencies (length
    5 a, largest 10 scale_j); harmonic 2 larger still (it must not count)."""
    scale = np.asarray(scale, float)
    a = scale[None, :] * np.array([1.0, 2.0, 1.0])[:, None]  # (frequency, point)
    amp = np.zeros((3, N, 2, 2))
    amp[..., 0, 0], amp[..., 1, 0] = 3 * a, 4 * a
    amp[..., :, 1] = 100.0
    return xr.Dataset({"response_amplitude": (("frequency", "point", "axis", "harmonic"),
                                              amp)},
                      coords={"point": [f"tip@{j}" for j in range(N)], "harmonic": [1, 2],
                              "frequency": [1.0, 2.0, 3.0]},
                      attrs={"mistuned_sectors": N, "engine_order": 1,
                             "mistuning_young": np.asarray(young, float),
                             "mistuning_mu": np.ones(N), "mistuning_wear": np.ones(N)})


def test_amplification_of_the_members_against_the_tuned_one(tmp_path):
    """Member 0 tuned (every blade 10 x 1e-6 at its peak), member 1 mistuned with one
    blade at 10 x 1.6e-6: amplifications 1 and 1.6; the bound (1 + sqrt(4)) / 2 = 1.5 is
    recorded (and here exceeded, as made-up numbers may); a failed member is NaN."""
    members = [Member(i, {}) for i in range(3)]
    records = [MemberRecord(0, "ok"), MemberRecord(1, "ok"), MemberRecord(2, "failed", "x")]
    runs = [sweep_member([1e-6] * N, [1.0] * N),
            sweep_member([1e-6, 1.6e-6, 0.5e-6, 1e-6], [1.0, 0.98, 1.02, 1.0])]
    for m, ds in zip(members, runs, strict=False):
        (tmp_path / m.folder_name).mkdir()
        ds.to_netcdf(tmp_path / m.folder_name / RESULTS_FILE, engine="h5netcdf")
    np.testing.assert_allclose(blade_response(runs[1]), [1e-5, 1.6e-5, 0.5e-5, 1e-5],
                               rtol=1e-15)
    out = aggregate(STUDY, members, records, tmp_path)
    amp = out["amplification_factor"].values
    np.testing.assert_allclose(amp[:2], [1.0, 1.6], rtol=1e-15)
    assert np.isnan(amp[2])
    assert out.attrs["whitehead_bound"] == 1.5 and out.attrs["tuned_members"] == "0"
    _, text = _summary(STUDY, records, out)
    assert "amplification factor: largest 1.6 over the members (tuned: members 0); " \
           "Whitehead's bound (1 + sqrt(4)) / 2 = 1.5" in text


def test_without_a_tuned_member_the_factor_is_nan(tmp_path):
    members = [Member(0, {})]
    (tmp_path / members[0].folder_name).mkdir()
    sweep_member([1e-6] * N, [1.1] * N).to_netcdf(
        tmp_path / members[0].folder_name / RESULTS_FILE, engine="h5netcdf")
    out = aggregate(STUDY, members, [MemberRecord(0, "ok")], tmp_path)
    assert np.isnan(out["amplification_factor"].values[0])
    assert out.attrs["tuned_members"] == "none"


def test_an_ensemble_perturbs_every_sectors_factor(tmp_path):
    """``[ensemble.perturb] "cyclic.mistuning.young" = {absolute = 0.02}`` on a base of N
    ones: member 0 is the tuned disk, the others draw N factors each (different, around 1)."""
    path, _ = write_sector_case(tmp_path, 8, 3, analysis='[analysis]\ntype = "periodic"\n'
                                'frequency = 9000.0\n')
    path.write_text(path.read_text() + "\n[cyclic.mistuning]\nyoung = [1.0, 1.0, 1.0, 1.0, "
                    "1.0, 1.0, 1.0, 1.0]\n")
    study = tmp_path / "mistuning.toml"
    study.write_text('base = "sector.toml"\n[ensemble]\nmembers = 3\nseed = 7\n'
                     '[ensemble.perturb]\n"cyclic.mistuning.young" = {absolute = 0.02}\n')
    members = expand(read_study(study))
    young = []
    for m in members:
        case = tmp_path / f"{m.folder_name}.toml"
        case.write_text(m.text)
        young.append(read_toml(case)[1]["cyclic"]["mistuning"]["young"])
    assert young[0] == [1.0] * 8
    for y in young[1:]:
        assert len(y) == 8 and len(set(y)) == 8 and max(abs(np.array(y) - 1)) < 0.1
    assert young[1] != young[2]


def test_wear_members_get_each_sectors_deepest_wear(tmp_path):
    """Wear members of a disk of N = 4 sectors of 2 contact nodes each (sector-major, as the
    disk numbers them): each sector's deepest final wear, and the member's deepest over the
    tuned member's (3 um over 2 um: 1.5); no FRF, so no amplification factor (NaN) and the
    summary says the wear only."""
    members = [Member(0, {}), Member(1, {})]
    finals = [np.array([1, 2, 2, 1, 0.5, 2, 1, 1]) * 1e-6,
              np.array([1, 3, 2, 1, 0.5, 1, 1, 1]) * 1e-6]
    for m, w, young in zip(members, finals, ([1.0] * N, [1.0, 1.01, 0.99, 1.0]),
                           strict=True):
        ds = xr.Dataset({"wear_depth": (("step", "contact_node"), np.vstack([0 * w, w])),
                         "cycles": ("step", [0.0, 1e5]),
                         "worn_volume": ("step", [0.0, w.sum() * 1e-6]),
                         "contact_position": (("contact_node", "dim"), np.zeros((8, 2)))},
                        attrs={"mistuned_sectors": N, "mistuning_young": np.array(young),
                               "mistuning_mu": np.ones(N), "mistuning_wear": np.ones(N)})
        (tmp_path / m.folder_name).mkdir()
        ds.to_netcdf(tmp_path / m.folder_name / RESULTS_FILE, engine="h5netcdf")
    records = [MemberRecord(0, "ok"), MemberRecord(1, "ok")]
    out = aggregate(STUDY, members, records, tmp_path)
    np.testing.assert_array_equal(out["sector_wear_depth"].values[1],
                                  np.array([3, 2, 1, 1]) * 1e-6)
    np.testing.assert_allclose(out["wear_amplification"].values, [1.0, 1.5], rtol=1e-15)
    assert np.isnan(out["amplification_factor"].values).all()
    _, text = _summary(STUDY, records, out)
    assert "deepest wear over the tuned disk's: largest 1.5" in text
    assert "amplification factor" not in text
