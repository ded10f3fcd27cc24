"""The ```python blocks of docs/api.md run as written (in order, one namespace, in a
temporary folder), so the documented API cannot drift from the code."""

import re
from pathlib import Path

import pytest

DOC = Path(__file__).resolve().parents[1] / "docs" / "api.md"


def python_blocks(text: str) -> list[str]:
    return re.findall(r"^```python\n(.*?)^```", text, flags=re.DOTALL | re.MULTILINE)


def test_api_doc_code_blocks_run(tmp_path, monkeypatch, capsys):
    blocks = python_blocks(DOC.read_text())
    assert len(blocks) >= 3
    monkeypatch.chdir(tmp_path)
    namespace: dict = {"__name__": "docs_api"}
    for i, code in enumerate(blocks):
        try:
            exec(compile(code, f"{DOC.name}, python block {i + 1}", "exec"), namespace)
        except Exception as exc:  # pragma: no cover - the message says which block failed
            pytest.fail(f"docs/api.md python block {i + 1} failed: {exc!r}\n{code}")
    out = capsys.readouterr().out
    assert "186 DOFs, 31 contact nodes" in out
    assert "can translate along x with nothing to hold it but friction" in out
