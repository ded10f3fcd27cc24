"""The documentation site's checker (scripts/check_site.py) and its configuration.

The checker's link pass is compared with links written by hand into a small site whose
faults are known (a missing page, a missing anchor, a missing image): it must report
exactly those, and nothing on the correct links. The site itself is built and opened in a
browser by .ci/run (mkdocs build --strict, then the checker), not here: the suite does not
need the docs extra."""

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _checker():
    spec = importlib.util.spec_from_file_location("check_site", ROOT / "scripts/check_site.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _page(path: Path, body: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(f"<html><body><article><h1 id='top'>t</h1>{body}</article></body></html>")


def test_link_pass_reports_exactly_the_broken_links(tmp_path):
    site = tmp_path / "site"
    _page(site / "index.html",
          "<a href='guide/'>ok dir</a><a href='guide/#usage'>ok anchor</a>"
          "<a href='missing/'>bad page</a><a href='guide/#nowhere'>bad anchor</a>"
          "<a href='https://example.org/x'>other site</a><a href='#top'>self</a>"
          "<img src='img/a.png'><img src='img/missing.png'>")
    _page(site / "guide" / "index.html", "<h2 id='usage'>u</h2><a href='../'>up</a>")
    (site / "img").mkdir()
    (site / "img" / "a.png").write_bytes(b"\x89PNG")
    problems, internal, external = _checker().check_links(site)
    assert external == 1
    assert internal == 8
    assert sorted(problems) == sorted([
        "index.html: link 'missing/' points to a missing file",
        "index.html: link 'guide/#nowhere': no id 'nowhere' in guide/index.html",
        "index.html: link 'img/missing.png' points to a missing file",
    ])


def test_every_docs_page_is_in_the_site_navigation():
    """mkdocs.yml's nav lists every page of docs/ (a page left out of the nav is built but
    unreachable from the menus; mkdocs only warns about it)."""
    nav = (ROOT / "mkdocs.yml").read_text()
    pages = [p.relative_to(ROOT / "docs").as_posix() for p in (ROOT / "docs").rglob("*.md")]
    assert pages
    missing = [p for p in pages if p not in nav]
    assert not missing, f"pages missing from mkdocs.yml nav: {missing}"


def test_the_api_reference_lists_every_public_name():
    """docs/reference/python.md (scripts/write_api_reference.py) has an entry for every name
    of fretwear's public table: a name added without its reference entry fails here."""
    import fretwear

    page = (ROOT / "docs" / "reference" / "python.md").read_text()
    missing = [n for n, m in fretwear._API.items() if f"::: {m}.{n}\n" not in page]
    assert not missing, f"run scripts/write_api_reference.py; missing: {missing}"


#: what a lab notebook leaves in a page: the machine's load, sessions and issue numbers of
#: the development, "before this version", commit hashes (a word of 7-40 hex digits with a
#: letter and a digit)
NOTEBOOK = [r"load\s+average", r"\bat\s+a\s+load\b", r"\bload\s+\d+(\.\d+)?\s*-\s*\d",
            r"\bloaded\s+machine", r"\bsession\b", r"\bissue\s+\d+", r"\bthe\s+issue'?s?\b",
            r"\bbefore\s+this\s+version", r"\b(?=[0-9a-f]*[a-f])(?=[0-9a-f]*\d)[0-9a-f]{7,40}\b"]


def _user_guide_pages() -> list[Path]:
    """The pages under "User guide" in mkdocs.yml's nav (and the home page)."""
    import re

    nav = (ROOT / "mkdocs.yml").read_text().split("\nnav:\n", 1)[1]
    guide = nav.split("  - User guide:\n", 1)[1].split("\n  - ", 1)[0]
    return [ROOT / "docs" / "index.md"] + [ROOT / "docs" / p for p in
                                           re.findall(r":\s*(\S+\.md)\s*$", guide, re.M)]


def test_user_guide_pages_read_as_a_guide_not_a_lab_notebook():
    """The user guide (tutorial, case files, Python API, results, studies, wear, time domain,
    gallery) says how to use fretwear, not how it was developed: no machine load, session,
    issue number, "before this version" or commit hash (those belong to docs/studies/). The
    pattern list is checked on phrases written here first, so that it cannot pass by
    matching nothing."""
    import re

    samples = ["(load\naverage 4-5)", "at a load of 12", "load 18-29", "on the loaded machine",
               "issue 29's second session", "The issue's oscillator", "before this version",
               "commit f956b9d"]
    for text in samples:
        assert any(re.search(p, text, re.I) for p in NOTEBOOK), text
    assert not any(re.search(p, "static load 20 MPa; 1e-6 m; 2e+11; 0.0001", re.I)
                   for p in NOTEBOOK)
    pages = _user_guide_pages()
    assert {"tutorial.md", "api.md", "wear.md", "study.md"} <= {p.name for p in pages}
    found = [f"docs/{page.name}: {m.group(0)!r}" for page in pages
             for p in NOTEBOOK for m in re.finditer(p, page.read_text(), re.I)]
    assert found == []
