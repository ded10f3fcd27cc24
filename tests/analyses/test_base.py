"""What an analysis is given (fretwear.analyses.base): run_case hands each analysis the case as
read from the file and a RunContext (results folder, --resume, progress); a resumed run sets
``resume`` in the context and never on the case.

Reference: the arguments run_case passes, caught on their way into the analysis's run
function, against what the call asked for and against the case loaded again from the file
(dataclass equality: the same text, tables and paths).
"""

import dataclasses
from pathlib import Path

import pytest
from helpers.cases import small_case

from fretwear.analyses import run as runner
from fretwear.analyses.base import RunContext
from fretwear.analyses.run import load_case, run_case

MODES = '[analysis]\ntype = "modes"\nn_modes = 2\n[output]\nfigures = false\nvtu = false\n'


@pytest.fixture
def caught(monkeypatch):
    """The (case, context) of every analysis run by run_case; the analysis still runs."""
    calls = []
    get = runner.get

    def spying_get(name):
        analysis = get(name)

        def run(model, table, case, context):
            calls.append((case, context))
            return analysis.run(model, table, case, context)

        return dataclasses.replace(analysis, run=run)

    monkeypatch.setattr(runner, "get", spying_get)
    return calls


@pytest.mark.parametrize("resume", [False, True])
def test_the_context_carries_resume_and_the_case_stays_as_read(tmp_path, caught, resume):
    path = small_case(tmp_path, MODES)
    out_dir = tmp_path / "out"
    out = run_case(path, out_dir, progress=False, resume=resume, echo=False)
    assert out.success and out.results == out_dir / "results.nc"
    ((case, context),) = caught
    assert context == RunContext(out_dir, resume=resume, progress=False)
    assert case == load_case(path)  # nothing of the run was written into it
    assert not hasattr(case, "resume")
    with pytest.raises(dataclasses.FrozenInstanceError):
        case.resume = True


def test_a_resumed_run_that_is_up_to_date_runs_nothing(tmp_path, caught):
    """--resume of a finished run: the results are read back, the analysis is not run."""
    path = small_case(tmp_path, MODES)
    run_case(path, tmp_path / "out", progress=False, echo=False)
    again = run_case(path, tmp_path / "out", progress=False, resume=True, echo=False)
    assert again.summary == "up to date" and len(caught) == 1


def test_run_context_is_a_frozen_record():
    c = RunContext(Path("out"))
    assert (c.out_dir, c.resume, c.progress) == (Path("out"), False, False)
    with pytest.raises(dataclasses.FrozenInstanceError):
        c.resume = True
