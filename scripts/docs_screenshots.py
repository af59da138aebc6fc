"""Render the built docs site in headless Chromium and check it is a rendered page.

    python scripts/docs_screenshots.py [SITE_DIR] [OUT_DIR]     # make test-docs

For the front page and one reference page: a screenshot (1280 x 900) and the DOM after
scripts ran. A page counts as rendered when the DOM holds the page's own heading (not an
error page), the screenshot is neither blank nor one colour, and the Material header bar is
drawn in the theme's indigo (the stylesheet loaded: unstyled HTML has no such bar). The
screenshots stay in OUT_DIR (default ``out/docs-screenshots``) for a person to look at.
The flags are the ones Chromium needs on a closed network (no background connections).
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy
from PIL import Image

ROOT = Path(__file__).resolve().parent.parent
PAGES = {
    "front": ("index.html", "otonav is a robotics stack in pure Python"),
    "reference-config": ("reference/config.html", "nav.dwa.horizon"),
}
"""Screenshot name: (page in the site, text its DOM must hold)."""
INDIGO = (63, 81, 181)
"""Material's ``primary: indigo`` header colour (#3f51b5)."""
FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
    "--window-size=1280,900",
]


def chromium(args: list[str], profile: str) -> subprocess.CompletedProcess[str]:
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        raise SystemExit("docs screenshots: no chromium (apt-get install chromium)")
    return subprocess.run(
        [exe, *FLAGS, f"--user-data-dir={profile}", *args],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )


def problems(png: Path) -> list[str]:
    """What makes this screenshot not a rendered page (empty: it is one)."""
    image = Image.open(png).convert("RGB")
    found = []
    if image.size != (1280, 900):
        found.append(f"size {image.size}, expected (1280, 900)")
    colours = image.getcolors(maxcolors=1_000_000) or []
    if len(colours) < 50:
        found.append(f"only {len(colours)} colours: blank")
    inked = float((numpy.asarray(image, dtype=numpy.int32).sum(axis=2) < 600).mean())
    if not 0.02 < inked < 0.9:
        found.append(f"{inked:.1%} of the pixels are not background")
    rgb = image.load()
    assert rgb is not None
    bar = [tuple(rgb[x, 20]) for x in range(0, 1280, 10)]  # type: ignore[arg-type]
    near = sum(all(abs(c - i) < 24 for c, i in zip(p, INDIGO, strict=True)) for p in bar)
    if near < len(bar) * 0.6:
        found.append(f"no indigo header bar (only {near} of {len(bar)} samples): unstyled?")
    return found


def main(argv: list[str]) -> int:
    site = Path(argv[0]) if argv else ROOT / "site"
    out = Path(argv[1]) if len(argv) > 1 else ROOT / "out" / "docs-screenshots"
    out.mkdir(parents=True, exist_ok=True)
    failed = False
    for name, (page, text) in PAGES.items():
        url = (site / page).resolve().as_uri()
        png = out / f"{name}.png"
        with tempfile.TemporaryDirectory() as profile:
            shot = chromium([f"--screenshot={png}", url], profile)
            dom = chromium(["--dump-dom", url], profile)
        found = [] if png.exists() else [f"no screenshot ({shot.stderr.strip()[-300:]})"]
        if text not in dom.stdout:
            found.append(f"the DOM does not hold {text!r}: an error page?")
        if png.exists():
            found += problems(png)
        print(
            f"{png.relative_to(ROOT) if png.is_relative_to(ROOT) else png}: "
            + ("rendered" if not found else "; ".join(found))
        )
        failed |= bool(found)
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
