"""Property-based: every case file generated from the schema gets a results file or one
clear message (tests/helpers/hostile.py says how cases are generated).

Reference: the command line's contract (README, "Using it"): exit 0 (1 when some solve did
not converge) with results.nc, or exit 2 with one line naming what is wrong; never a
traceback, never a hang, never a file outside the output folder. The examples are
derandomized (the same cases at every run); studies/hostile_inputs.py runs the same generator
over more cases and counts the outcomes.
"""

import tempfile
from pathlib import Path

import pytest
from helpers import hostile, hostile_studies
from hypothesis import HealthCheck, Phase, given, settings


def check(generated) -> None:
    case, changes = generated
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp) / "work"
        folder.mkdir()
        before = set(Path(tmp).rglob("*"))
        rc, err, outcome = hostile.run_generated(case, folder)
        what = "; ".join(changes)
        assert outcome in ("ran", "message"), f"{what}: {outcome}"
        if outcome == "message":
            lines = [ln for ln in err.strip().splitlines() if ln.strip()]
            assert len(lines) == 1 and lines[0].startswith("error:"), f"{what}: {err!r}"
        else:
            assert rc in (0, 1) and (folder / "out" / "results.nc").is_file(), what
        new = set(Path(tmp).rglob("*")) - before
        outside = [p for p in new if p.name not in ("case.toml", *hostile.SECTOR_FILES)
                   and p != folder / "out" and folder / "out" not in p.parents]
        assert not outside, f"{what}: wrote {outside}"


@settings(max_examples=40, deadline=None, derandomize=True, database=None,
          suppress_health_check=list(HealthCheck),
          phases=(Phase.explicit, Phase.generate))  # no shrinking: each run costs seconds
@given(hostile.hostile_cases(analyses=("modes", "frf", "periodic")))
def test_generated_cases_fast_analyses(generated):
    check(generated)


@pytest.mark.slow
@settings(max_examples=200, deadline=None, derandomize=True, database=None,
          suppress_health_check=list(HealthCheck),
          phases=(Phase.explicit, Phase.generate))  # no shrinking: each run costs seconds
@given(hostile.hostile_cases())
def test_generated_cases_every_analysis(generated):
    check(generated)


@settings(max_examples=12, deadline=None, derandomize=True, database=None,
          suppress_health_check=list(HealthCheck),
          phases=(Phase.explicit, Phase.generate))  # no shrinking
@given(hostile_studies.hostile_studies())
def test_generated_study_files(generated):
    """Study files of the four kinds with hostile values (tests/helpers/hostile_studies.py),
    read, expanded, sized and collected by `fretwear study --collect` (no member runs): the
    same contract as case files, study.nc for one that ran."""
    kind, study, changes = generated
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp) / "work"
        folder.mkdir()
        before = set(Path(tmp).rglob("*"))
        rc, err, outcome = hostile_studies.run_study_file(kind, study, folder)
        what = f"{kind}: " + "; ".join(changes)
        assert outcome in ("ran", "message"), f"{what}: {outcome}"
        if outcome == "message":
            lines = [ln for ln in err.strip().splitlines() if ln.strip()]
            assert len(lines) == 1 and lines[0].startswith("error:"), f"{what}: {err!r}"
        else:
            assert (folder / "out" / "study.nc").is_file(), what
        new = set(Path(tmp).rglob("*")) - before
        outside = [p for p in new if p.name not in ("base.toml", "study.toml")
                   and p != folder / "out" and folder / "out" not in p.parents]
        assert not outside, f"{what}: wrote {outside}"
