"""Every relative link of the documentation points to an existing file.

Checked in README.md, docs/**/*.md and studies/README.md: the markdown links and images
(``[text](path)``, ``![alt](path)``, relative to the file that holds them) and the paths of
the repository's documentation, benchmark and study files named in the text
(``docs/...``, ``benchmarks/...``, ``studies/...``, relative to the repository root), so that
moving a file without updating its mentions fails here.
"""

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FILES = sorted([ROOT / "README.md", *(ROOT / "docs").rglob("*.md"),
                *(ROOT / "studies").glob("*.md")])
FENCE = re.compile(r"^(```|~~~).*?^\1", re.S | re.M)
CODE = re.compile(r"`[^`\n]*`")
LINK = re.compile(r"!?\[[^\]\n]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
PATH = re.compile(r"(?<![\w./-])((?:docs|benchmarks|studies)/[\w./-]*[\w-]"
                  r"\.(?:md|py|png|json|npz))")


def _rel(path: Path) -> str:
    return path.relative_to(ROOT).as_posix()


def _links(text: str) -> list[str]:
    """Targets of the markdown links outside code (fenced blocks and code spans)."""
    return LINK.findall(CODE.sub("", FENCE.sub("", text)))


def test_the_documentation_files_are_found():
    names = {_rel(f) for f in FILES}
    assert {"README.md", "docs/theory.md", "docs/wear.md"} <= names


@pytest.mark.parametrize("doc", FILES, ids=_rel)
def test_relative_links_point_to_existing_files(doc):
    text = doc.read_text(encoding="utf-8")
    missing = []
    for target in _links(text):
        if re.match(r"[a-zA-Z][a-zA-Z0-9+.-]*:", target) or target.startswith("#"):
            continue  # a URL or an anchor in the same page
        path = target.split("#", 1)[0]
        if not (doc.parent / path).exists():
            missing.append(target)
    assert not missing, f"{_rel(doc)}: links to missing files: {missing}"


@pytest.mark.parametrize("doc", FILES, ids=_rel)
def test_named_repository_files_exist(doc):
    text = LINK.sub(lambda m: m.group(0).replace(m.group(1), ""), doc.read_text(encoding="utf-8"))
    missing = sorted({p for p in PATH.findall(text) if not (ROOT / p).exists()})
    assert not missing, f"{_rel(doc)}: names files that do not exist: {missing}"


def test_the_checks_see_links_and_paths():
    """The patterns find what they are meant to (and nothing in code)."""
    text = ("see [a](x/a.md#s), ![f](figures/f.png) and [u](https://e.org/x);\n"
            "`b[0](c)` and docs/wear.md, `studies/run_it.py`.\n```\n[no](link.md)\n```\n")
    assert _links(text) == ["x/a.md#s", "figures/f.png", "https://e.org/x"]
    assert PATH.findall(text) == ["docs/wear.md", "studies/run_it.py"]
