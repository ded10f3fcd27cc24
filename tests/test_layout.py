"""tests/ mirrors src/ (docs/architecture.md): every module of src/fretwear has a test
module of its own, ``tests/<package>/test_<module>.py`` (``tests/test_<module>.py`` for a
top-level module); package ``__init__.py`` and ``__main__.py`` files are the exception.

Reference: the file trees themselves, listed here with pathlib.
"""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src" / "fretwear"
TESTS = ROOT / "tests"

#: Modules allowed to have no test module yet, relative to src/fretwear (a module added before
#: its tests, named here with the branch that adds them). Empty: every module has its test
#: module. An entry that has its test module (or no longer exists) fails
#: test_the_allowance_names_only_modules_without_tests.
PENDING: set[str] = set()


def modules() -> list[str]:
    return sorted(p.relative_to(SRC).as_posix() for p in SRC.rglob("*.py")
                  if p.name not in ("__init__.py", "__main__.py"))


def mirror_of(module: str) -> Path:
    """Where the test module of ``module`` (relative to src/fretwear) lives."""
    path = Path(module)
    return TESTS / path.parent / f"test_{path.name}"


def test_every_module_has_its_test_module():
    assert len(modules()) > 50  # the tree was found (a wrong root would pass vacuously)
    missing = [m for m in modules() if not mirror_of(m).is_file() and m not in PENDING]
    assert not missing, "modules without a test module: " + ", ".join(
        f"{m} (expected {mirror_of(m).relative_to(ROOT)})" for m in missing)


def test_the_allowance_names_only_modules_without_tests():
    stale = sorted(m for m in PENDING if m not in modules() or mirror_of(m).is_file())
    assert not stale, ("remove from PENDING in tests/test_layout.py (the module has its test "
                       "module now, or is gone): " + ", ".join(stale))


def test_the_hb_layers_in_the_docs_are_the_contract():
    """docs/architecture.md's diagram of the layers inside ``hb`` lists the layers of
    pyproject.toml's import-linter contract for ``fretwear.hb``, in the same order (what
    lint-imports enforces is what a reader is told). Reference: the two files, parsed."""
    import tomllib

    conf = tomllib.loads((ROOT / "pyproject.toml").read_text())
    contract = next(c for c in conf["tool"]["importlinter"]["contracts"]
                    if c.get("containers") == ["fretwear.hb"])
    text = (ROOT / "docs" / "architecture.md").read_text()
    start = text.index("```", text.index("Inside `hb`, a module imports only the layers"))
    block = text[start + 3:text.index("```", start + 3)]
    shown = [" | ".join(m.strip() for m in layer.split("|")) for layer in
             " ".join(block.split()).split(">")]
    assert len(contract["layers"]) > 5  # the contract was found
    assert shown == contract["layers"]
