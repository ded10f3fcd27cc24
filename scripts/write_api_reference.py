"""Write docs/reference/python.md: one entry per public name of ``fretwear`` (its ``_API``
table), grouped by the stage of the module that defines it, rendered by mkdocstrings from the
docstrings when the site is built.

    python scripts/write_api_reference.py

tests/test_docs_site.py checks that the page lists every public name: run this after adding one.
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "reference" / "python.md"

#: (heading, module prefixes) in the order a user meets them
STAGES = [
    ("Models", ("fretwear.model",)),
    ("Linear analyses", ("fretwear.linear",)),
    ("Harmonic balance: condensation, periodic states, sweeps, stability",
     ("fretwear.hb", "fretwear.api")),
    ("Wear", ("fretwear.wear",)),
    ("Time domain", ("fretwear.timedomain",)),
    ("Case files, results and studies", ("fretwear.analyses", "fretwear.io", "fretwear.study")),
    ("Threads and errors", ("fretwear.threads", "fretwear.errors")),
]


def page() -> str:
    sys.path.insert(0, str(ROOT / "src"))
    import fretwear

    lines = ["# Python API reference", "",
             "Every public name of `import fretwear as fw`, generated from its docstring. The",
             "guide with runnable examples is [the Python API page](../api.md); the",
             "[tutorial](../tutorial.md) builds a model from nothing.", ""]
    placed = set()
    for heading, prefixes in STAGES:
        names = [(n, m) for n, m in fretwear._API.items()
                 if m.startswith(prefixes) and n not in placed]
        if not names:
            continue
        lines += [f"## {heading}", ""]
        for name, module in names:
            placed.add(name)
            lines += [f"::: {module}.{name}", "    options:", "      heading_level: 3", ""]
    left = sorted(set(fretwear._API) - placed)
    if left:
        lines += ["## Other", ""]
        for name in left:
            lines += [f"::: {fretwear._API[name]}.{name}", "    options:",
                      "      heading_level: 3", ""]
    return "\n".join(lines).rstrip() + "\n"


if __name__ == "__main__":
    PAGE.parent.mkdir(parents=True, exist_ok=True)
    PAGE.write_text(page())
    print(f"wrote {PAGE.relative_to(ROOT)}")
