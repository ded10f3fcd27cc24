"""Small case and study files for the study tests (tests/study/)."""

from __future__ import annotations

import os
from pathlib import Path

from helpers.cases import ROOT, small_case

PERIODIC = """[analysis]
type = "periodic"
frequency = 7e3
harmonics = 3
n_samples = 32
"""

SWEEP = """[analysis]
type = "sweep"
f_min = 6e3
f_max = 8e3
n_points = 7
spacing = "linear"
harmonics = 1
n_samples = 16
linear_references = []
"""

WEAR = """[analysis]
type = "wear"
quasi_static = true
harmonics = 3
n_samples = 32
tolerance = 0.05
max_cycles = 3e5
checkpoint_every_s = 0.0
"""


def base_case(tmp_path: Path, analysis: str = PERIODIC, name: str = "beam.toml") -> Path:
    """The shipped beam on a 10 x 2 mesh with ``analysis``; no ParaView files, no figures."""
    path = small_case(tmp_path, analysis, name)
    path.write_text(path.read_text() + "\n[output]\nvtu = false\nfigures = false\n")
    return path


def study_file(tmp_path: Path, body: str, base: str = "beam.toml",
               name: str = "study.toml") -> Path:
    path = tmp_path / name
    path.write_text(f'title = "test study"\nbase = "{base}"\n{body}')
    return path


def worker_env() -> dict:
    """The environment of worker processes started by a test: this source tree first."""
    src = str(ROOT / "src")
    env = dict(os.environ)
    env["PYTHONPATH"] = src + os.pathsep + env.get("PYTHONPATH", "")
    env["OPENBLAS_NUM_THREADS"] = "1"
    return env
