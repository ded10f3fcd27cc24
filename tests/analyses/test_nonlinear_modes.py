"""The ``nonlinear-modes`` analysis from case files: its input errors are one line naming the
key (the closed-form check of its results is tests/test_examples.py, on the shipped Jenkins
example; the method itself is tested in tests/hb/test_nonlinear_modes.py).

Each case is the shipped Jenkins example with one key changed; nothing is computed before the
error (no results folder is made)."""

import shutil

import pytest
from helpers.cases import EXAMPLES, run, with_key

EXAMPLE = EXAMPLES / "jenkins-nonlinear-modes.toml"


def jenkins_case(tmp_path, line: str):
    for name in ("jenkins-K.mtx", "jenkins-M.mtx"):
        shutil.copy(EXAMPLES / name, tmp_path)
    text = EXAMPLE.read_text()
    head, analysis = text[: text.index("[analysis]")], text[text.index("[analysis]"):]
    path = tmp_path / "jenkins.toml"
    path.write_text(head + with_key(analysis, line))
    return path


@pytest.mark.parametrize("line, message", [
    ("mode = 0", "analysis.mode = 0: expected an integer >= 1"),
    ('interface = "glued"', 'analysis.interface = "glued": expected one of "stuck", "sliding"'),
    ("amplitude_max = 1e-7", "analysis.amplitude_max = 1e-07: expected a value above "
                             "amplitude_min = 1e-06 m kg^0.5"),
    ("n_amplitudes = 1", "analysis.n_amplitudes = 1: expected an integer in [2, 10000]"),
    # the mode's structure is reduced on its own modes: a condensation key would be ignored
    ('condensation = "modal"', "unknown key 'condensation' in [analysis]"),
])
def test_bad_nonlinear_modes_input_gives_one_clear_line(tmp_path, capsys, line, message):
    status, out, err = run(jenkins_case(tmp_path, line), capsys)
    assert status == 2
    assert err.startswith(f"error: {message}") and err.count("\n") == 1, err
    assert not any(p.is_dir() for p in tmp_path.iterdir())
