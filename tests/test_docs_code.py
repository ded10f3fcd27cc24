"""Every ```python block of the user docs runs as written (docs/api.md has its own test,
tests/test_docs_api.py): each page's blocks in order, in one namespace, in a temporary folder,
with figures drawn off screen. A block that cannot run here (it starts a cluster, or needs one)
is preceded by an HTML comment ``<!-- not run by tests/test_docs_code.py: why -->`` and is only
compiled, so a syntax error still fails. The comparison is with the docs themselves: a page
whose example no longer matches the API fails here, not on a user's first day."""

import re
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[1] / "docs"
BLOCK = re.compile(r"(<!-- not run[^>]*-->\n)?^```python\n(.*?)^```", re.DOTALL | re.MULTILINE)
PAGES = sorted(p for p in DOCS.glob("*.md") if p.name != "api.md" and BLOCK.search(p.read_text()))


def test_the_pages_with_code_are_found():
    """The pages whose examples were reported not to run are among those checked."""
    names = {p.name for p in PAGES}
    assert {"results.md", "study.md", "transient.md", "wear.md"} <= names


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_doc_code_blocks_run(page, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    import matplotlib

    matplotlib.use("Agg")
    namespace: dict = {"__name__": f"docs_{page.stem}"}
    for i, match in enumerate(BLOCK.finditer(page.read_text())):
        skip, code = match.group(1), match.group(2)
        compiled = compile(code, f"{page.name}, python block {i + 1}", "exec")
        if skip:
            continue
        try:
            exec(compiled, namespace)
        except Exception as exc:  # pragma: no cover - the message says which block failed
            pytest.fail(f"docs/{page.name} python block {i + 1} failed: {exc!r}\n{code}")
