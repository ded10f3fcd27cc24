"""Small case files and the check of results files against docs/results.md, shared by the tests
of the analyses run from case files."""

import re
from pathlib import Path

from fretwear import cli

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "src" / "fretwear" / "examples"
LINEAR_EXAMPLE = EXAMPLES / "beam-linear-frf.toml"


def small_case(tmp_path: Path, analysis: str, name: str = "beam.toml") -> Path:
    """The shipped beam on a 10 x 2 mesh with another ``[analysis]`` table."""
    text = LINEAR_EXAMPLE.read_text()
    for old, new in {"nx = 30": "nx = 10", "ny = 4 ": "ny = 2 "}.items():
        assert old in text
        text = text.replace(old, new)
    path = tmp_path / name
    path.write_text(text[: text.index("[analysis]")] + analysis)
    return path


def with_key(analysis: str, line: str) -> str:
    """``analysis`` with the key of ``line`` set by ``line`` (replaced or added)."""
    key = line.split("=")[0].strip()
    kept = [x for x in analysis.splitlines() if x.split("=")[0].strip() != key]
    return "\n".join(kept + [line]) + "\n"


def run(path: Path, capsys) -> tuple[int, str, str]:
    status = cli.main(["run", str(path), "--no-progress"])
    out = capsys.readouterr()
    return status, out.out, out.err


# --- the documented schema ------------------------------------------------------------------
def doc_rows(section: str | None = None) -> dict[str, tuple[str, str]]:
    """name -> (dimensions, units) from the tables of docs/results.md: the shared sections
    (dimensions, geometry) and, if given, the section ``## `section```."""
    rows, current = {}, None
    for line in (ROOT / "docs" / "results.md").read_text().splitlines():
        if line.startswith("## "):
            current = line[3:].strip()
        shared = current in ("Rules for every analysis",)
        if not (shared or current == f"`{section}`"):
            continue
        m = re.match(r"\| `(\w+)` \|([^|]*)\|([^|]*)\|", line)  # a scalar: empty dimensions
        if m:
            rows[m.group(1)] = (m.group(2).strip(), m.group(3).strip())
    return rows


def section_dimensions(section: str) -> set[str]:
    """The names in backquotes of the ``Dimensions:`` paragraph of a section of
    docs/results.md (label coordinates described in prose, e.g. the wear ``contact_state``)."""
    text = (ROOT / "docs" / "results.md").read_text()
    part = text.split(f"## `{section}`", 1)[1].split("\n## ", 1)[0]
    para = part.split("Dimensions:", 1)[1].split("\n\n", 1)[0] if "Dimensions:" in part else ""
    return set(re.findall(r"`(\w+)`", para))


def check_documented(ds, section: str) -> None:
    docs = doc_rows(section)
    prose = section_dimensions(section)
    for name, var in list(ds.coords.items()) + list(ds.data_vars.items()):
        if name in ds.dims and name in prose and name not in docs:
            assert var.attrs["units"] == "1" and var.attrs["long_name"], name
            continue  # a label coordinate described in the section's Dimensions paragraph
        assert name in docs, f"{name} is not documented in docs/results.md ({section})"
        assert var.attrs["units"] == docs[name][1], name
        assert var.attrs["long_name"], name
    for name, var in ds.data_vars.items():
        assert ", ".join(var.dims) == docs[name][0], name


# the transient analysis in its "fixed" mode: 20 periods of 64 steps at 1 kHz
FIXED = """[analysis]
type = "transient"
frequency = 1e3
mode = "fixed"
n_periods = 20
steps_per_period = 64
harmonics = 3
"""


#: a small steel block (10 x 2 Q4) pressed on a flat and pushed back and forth: the model of
#: the wear tests (quasi-static partial slip; a run of a few hundred steps takes seconds)
WEAR_BLOCK = """
[model]
type = "rectangle"
length = 0.02
height = 0.004
nx = 10
ny = 2
thickness = 0.01
[material]
E = 210e9
nu = 0.3
rho = 7800.0
[[springs]]
at = "bottom_left"
direction = "x"
stiffness = 1e5
[[loads]]
boundary = "top"
pressure = 1e6
[[loads]]
boundary = "right"
pressure = 7.5e5
waveform = "sin"
[contact]
boundary = "bottom"
normal = [0.0, -1.0]
mu = 0.3
wear_coefficient = 1e-11
[observed]
Pe = [0.02, 0.002]
"""
