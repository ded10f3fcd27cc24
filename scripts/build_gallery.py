"""Write the gallery page of the documentation site: every shipped example with its purpose, the
command that runs it, and its figures.

    python scripts/examples_regression.py run OUT          # runs the examples (a few minutes)
    python scripts/build_gallery.py OUT [--note "..."]     # docs/gallery.md + docs/gallery/

Each example's title and first comment block come from its case file
(``src/fretwear/examples/NAME.toml``); its figures are the PNG files that ``fretwear run``
wrote into ``OUT/NAME/``, copied to ``docs/gallery/NAME/`` reduced to at most 1000 pixels
wide (palette PNG) so that the repository stays small. An example without figures in ``OUT``
is listed with its command only. ``examples_regression.py`` shortens the long examples (fewer
frequencies or cycles, its ``SHORTEN`` table): the page says which figures come from a
shortened run.
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "src" / "fretwear" / "examples"
DOCS = ROOT / "docs"
WIDTH = 1000  # pixels


def _description(case: Path) -> str:
    """The first comment block of a case file, as one paragraph."""
    lines = []
    for line in case.read_text().splitlines():
        if not line.startswith("#"):
            break
        lines.append(line.lstrip("#").strip())
    return " ".join(lines)


def _shrink(src: Path, dst: Path) -> None:
    from PIL import Image

    dst.parent.mkdir(parents=True, exist_ok=True)
    with Image.open(src) as im:
        im = im.convert("RGB")
        if im.width > WIDTH:
            im = im.resize((WIDTH, round(im.height * WIDTH / im.width)), Image.LANCZOS)
        im.quantize(colors=256, method=Image.Quantize.MEDIANCUT).save(dst, optimize=True)


def build(out: Path) -> str:
    sys.path.insert(0, str(ROOT / "scripts"))
    from examples_regression import SHORTEN

    target = DOCS / "gallery"
    if target.exists():
        shutil.rmtree(target)
    parts = ["# Gallery of the shipped examples", "",
             "Every example ships with fretwear as a case file: `fretwear example list` lists",
             "them, `fretwear example run NAME -o OUT` runs one and writes `OUT/results.nc`,",
             "its figures and ParaView files, and `fretwear example show NAME` prints the case",
             "file to start a model of your own from. The figures below are those runs'",
             "own figures, unedited. Examples marked *shortened* were run with fewer",
             "frequencies or cycles than they ship with (to keep the page quick to rebuild);",
             "the shipped case file gives the full figure.", ""]
    for case in sorted(EXAMPLES.glob("*.toml")):
        name = case.stem
        title = tomllib.loads(case.read_text()).get("title", name)
        parts += [f"## {title}", "", f"`fretwear example run {name} -o {name}`", "",
                  _description(case), ""]
        figures = sorted((out / name).glob("*.png")) if (out / name).is_dir() else []
        if name in SHORTEN and figures:
            keys = ", ".join(f"{k} = {v}" for k, v in SHORTEN[name].items()
                             if not isinstance(v, dict))
            parts += [f"*Shortened for this page: {keys or 'fewer frequencies'}.*", ""]
        for fig in figures:
            _shrink(fig, target / name / fig.name)
            parts += [f"![{name}: {fig.stem}](gallery/{name}/{fig.name})", ""]
        if not figures:
            parts += ["*No figure on this page: run the example to see them.*", ""]
    return "\n".join(parts).rstrip() + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="a folder written by examples_regression.py run")
    args = parser.parse_args(argv)
    if not args.out.is_dir():
        print(f"build_gallery: {args.out} is not a folder; expected the output of "
              "scripts/examples_regression.py run")
        return 1
    (DOCS / "gallery.md").write_text(build(args.out))
    n = len(list((DOCS / "gallery").rglob("*.png")))
    print(f"wrote docs/gallery.md and {n} figures in docs/gallery/")
    return 0


if __name__ == "__main__":
    sys.exit(main())
