"""Check the built documentation site: every internal link and image resolves, and every page
renders in a real headless browser with its images loaded and no console error.

    mkdocs build            # writes site/
    python scripts/check_site.py site [--no-browser] [--chromium /usr/bin/chromium]

Two passes:

1. Links (no browser): every ``href`` and ``src`` of every HTML page that points inside the
   site must name a file that exists, and a ``#fragment`` must name an ``id`` of that page.
   Links to other sites are counted, not fetched (CI has no business depending on them).
2. Browser: each page is served over HTTP from a local server and opened in headless
   Chromium through Playwright; the page must have a title heading, every ``<img>`` must
   have loaded (``complete`` and a natural width > 0), and the page must log no console
   error, raise no JavaScript error and have no request that failed.

Exits 1 with one line per problem, 0 when the site is clean; prints what it checked.
Needs the ``docs`` extra (``pip install ".[docs]"``) and a Chromium: Debian's ``chromium``
package (``/usr/bin/chromium``, what ``.ci/run`` installs) or Playwright's own
(``playwright install chromium``).
"""

from __future__ import annotations

import argparse
import functools
import http.server
import shutil
import sys
import threading
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit


class _Page(HTMLParser):
    """The ids, links and image sources of one HTML page."""

    def __init__(self):
        super().__init__()
        self.ids: set[str] = set()
        self.links: list[str] = []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if a.get("id"):
            self.ids.add(a["id"])
        if tag == "a" and a.get("name"):
            self.ids.add(a["name"])
        for key in ("href", "src"):
            if a.get(key) and tag in ("a", "img", "script", "link", "source"):
                self.links.append(a[key])


def _parse(path: Path) -> _Page:
    page = _Page()
    page.feed(path.read_text(encoding="utf-8", errors="replace"))
    return page


def _target(site: Path, page: Path, link: str) -> tuple[Path | None, str]:
    """The file a relative link points to (None for another site) and its fragment."""
    parts = urlsplit(link)
    if parts.scheme or parts.netloc or link.startswith(("mailto:", "data:", "javascript:")):
        return None, ""
    if not parts.path:
        return page, parts.fragment
    base = site if parts.path.startswith("/") else page.parent
    target = (base / unquote(parts.path.lstrip("/"))).resolve()
    if target.is_dir() or parts.path.endswith("/"):
        target = target / "index.html"
    return target, parts.fragment


def check_links(site: Path) -> tuple[list[str], int, int]:
    """Problems, the number of internal links checked and of external links seen."""
    pages = sorted(site.rglob("*.html"))
    parsed = {p.resolve(): _parse(p) for p in pages}
    problems, internal, external = [], 0, 0
    for page, info in parsed.items():
        for link in info.links:
            target, fragment = _target(site, page, link)
            if target is None:
                external += 1
                continue
            internal += 1
            rel = page.relative_to(site.resolve())
            if not target.exists():
                problems.append(f"{rel}: link {link!r} points to a missing file")
                continue
            if fragment and target.suffix == ".html":
                ids = parsed[target].ids if target in parsed else _parse(target).ids
                if fragment not in ids:
                    problems.append(f"{rel}: link {link!r}: no id {fragment!r} in "
                                    f"{target.relative_to(site.resolve())}")
    return problems, internal, external


def _serve(site: Path) -> tuple[http.server.ThreadingHTTPServer, str]:
    handler = functools.partial(_QuietHandler, directory=str(site))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server, f"http://127.0.0.1:{server.server_address[1]}/"


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):  # the checker reports, not the server
        pass


_IMAGES = """() => Array.from(document.images).filter(
    i => !(i.complete && i.naturalWidth > 0)).map(i => i.getAttribute('src'))"""


def check_in_browser(site: Path, chromium: str | None) -> tuple[list[str], int, int]:
    """Problems, pages opened and images seen loaded, in headless Chromium."""
    from playwright.sync_api import sync_playwright

    pages = sorted(p for p in site.rglob("*.html") if p.name != "404.html")
    server, root = _serve(site)
    problems, images = [], 0
    try:
        with sync_playwright() as pw:
            kwargs = {"args": ["--no-sandbox"]}
            if chromium:
                kwargs["executable_path"] = chromium
            browser = pw.chromium.launch(**kwargs)
            tab = browser.new_page()
            errors: list[str] = []
            tab.on("console", lambda m: errors.append(f"console {m.type}: {m.text}")
                   if m.type == "error" else None)
            tab.on("pageerror", lambda e: errors.append(f"JavaScript error: {e}"))
            tab.on("requestfailed", lambda r: errors.append(f"request failed: {r.url}"))
            for page in pages:
                rel = page.relative_to(site).as_posix()
                errors.clear()
                response = tab.goto(root + rel, wait_until="load")
                tab.wait_for_load_state("networkidle")  # the search index's worker too
                if response is None or response.status != 200:
                    problems.append(f"{rel}: HTTP {None if response is None else response.status}")
                if tab.locator("article h1").count() == 0:
                    problems.append(f"{rel}: no title heading rendered")
                broken = tab.evaluate(_IMAGES)
                problems += [f"{rel}: image {src!r} did not load" for src in broken]
                images += tab.evaluate("() => document.images.length") - len(broken)
                problems += [f"{rel}: {e}" for e in errors]
            browser.close()
    finally:
        server.shutdown()
    return problems, len(pages), images


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("site", type=Path, help="the built site (mkdocs build -> site/)")
    parser.add_argument("--no-browser", action="store_true", help="links only")
    parser.add_argument("--chromium", default=None,
                        help="Chromium executable (default: /usr/bin/chromium if present, "
                             "else Playwright's own)")
    args = parser.parse_args(argv)
    site = args.site.resolve()
    if not (site / "index.html").exists():
        print(f"check_site: {site} has no index.html; expected a built site (mkdocs build)")
        return 1
    problems, internal, external = check_links(site)
    print(f"links: {internal} internal links checked, {external} links to other sites "
          f"not fetched, {len(problems)} problems")
    if not args.no_browser:
        chromium = args.chromium or shutil.which("chromium") or shutil.which("chromium-browser")
        found, n_pages, n_images = check_in_browser(site, chromium)
        print(f"browser: {n_pages} pages opened in headless Chromium "
              f"({chromium or 'Playwright build'}), {n_images} images loaded, "
              f"{len(found)} problems")
        problems += found
    for p in problems:
        print("  " + p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
