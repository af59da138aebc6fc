"""Render the built docs site in headless Chromium and check it renders and reads well.

    python scripts/docs_screenshots.py [SITE_DIR] [OUT_DIR]     # make test-docs

For one page of each kind (front, tutorial, how-to, concept, the long references, API):
a screenshot (1280 x 900) and the DOM after scripts ran. A page counts as rendered when
the DOM holds the page's own heading (not an error page), the screenshot is neither
blank nor one colour, and the Material header bar is drawn in the theme's indigo (the
stylesheet loaded). It reads well when, laid out at that width (a script measures it in
the page, issue 39): no code block or table runs past the content column (clipped), a
page with three or more sections shows its table of contents, the page title is not
repeated as the first heading, and the sidebar's site name does not overlap its first
entry. Every page of the site is also searched for a raw Sphinx role (``:class:`` ...)
or reST ``::`` marker in its text. The screenshots stay in OUT_DIR (default
``out/docs-screenshots``) for a person to look at. The flags are the ones Chromium
needs on a closed network (no background connections).
"""

from __future__ import annotations

import html
import json
import re
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
    "tutorial": ("getting-started/tutorial.html", "otonav for ROS 2 users"),
    "how-to-own-robot": ("how-to/own-robot.html", "Put your own robot in"),
    "how-to-own-node": ("how-to/own-node.html", "Write your own node"),
    "concept-launch": ("concepts/launch.html", "launch file"),
    "reference-config": ("reference/config.html", "nav.dwa.horizon"),
    "reference-cli": ("reference/cli.html", "otonav echo"),
    "api-runtime": ("reference/api/runtime.html", "otonav.runtime"),
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


LAYOUT_CHECK = """<script>
window.addEventListener("load", () => {
  const found = [];
  const main = document.querySelector(".md-content");
  const column = main.getBoundingClientRect();
  for (const el of main.querySelectorAll("pre > code, .md-typeset__table, table")) {
    const box = el.getBoundingClientRect();
    if (el.scrollWidth > el.clientWidth + 1 || box.right > column.right + 1) {
      const what = el.tagName === "CODE" ? "code block" : "table";
      found.push(`clipped ${what}: ${el.textContent.trim().slice(0, 50)}`);
    }
  }
  const sections = main.querySelectorAll("h2").length;
  const toc = document.querySelector(".md-sidebar--secondary");
  if (sections >= 3 && (!toc || getComputedStyle(toc).display === "none"
      || !toc.querySelector(".md-nav__link"))) {
    found.push(`no table of contents (${sections} sections)`);
  }
  const h1 = main.querySelector("h1"), h2 = main.querySelector("h2");
  const text = (el) => el.textContent.replace("\u00b6", "").trim();
  if (h1 && h2 && text(h1) === text(h2)) found.push(`title repeated: ${text(h1)}`);
  const name = document.querySelector(".md-nav--primary > .md-nav__title");
  const first = document.querySelector(".md-nav--primary > .md-nav__list > .md-nav__item");
  if (name && first && getComputedStyle(name).display !== "none") {
    const a = name.getBoundingClientRect(), b = first.getBoundingClientRect();
    if (a.height > 0 && a.bottom > b.top - 4) {  // touching: it overlaps once scrolled
      found.push("sidebar: the site name sits on its first entry");
    }
  }
  const out = document.createElement("pre");
  out.id = "otonav-layout";
  out.textContent = JSON.stringify(found);
  document.body.appendChild(out);
});
</script>"""
"""Measures the laid-out page (see the module docstring) and writes what it found into
the DOM, where ``--dump-dom`` shows it."""
RAW_ROLE = re.compile(
    r":(?:py:)?(?:class|meth|func|data|attr|mod|exc|obj|const):[`~\w]|\w::(?:\s|$)"
)
"""A Sphinx role (its backticks rendered as code, the text reads ``:class:Name``), or a
reST literal-block marker, left as text."""


def raw_roles(site: Path) -> list[str]:
    """One line per page whose text still holds a Sphinx role or a ``::`` marker."""
    found = []
    for page in sorted(site.rglob("*.html")):
        if "adr" in page.parts:  # the ADRs quote roles on purpose
            continue
        text = re.sub(r"<[^>]+>", "", page.read_text(errors="replace"))
        hits = RAW_ROLE.findall(html.unescape(text))
        if hits:
            found.append(f"{page.relative_to(site)}: {len(hits)} raw Sphinx role(s)")
    return found


def layout(site: Path, page: str, profile: str) -> list[str]:
    """What the in-page measurement found on ``page`` (a copy with the check added)."""
    source = site / page
    probe = source.with_name(f".layout-{source.name}")
    probe.write_text(source.read_text().replace("</body>", LAYOUT_CHECK + "</body>"))
    try:
        dom = chromium(["--virtual-time-budget=5000", "--dump-dom", probe.as_uri()], profile)
    finally:
        probe.unlink()
    match = re.search(r'<pre id="otonav-layout">(.*?)</pre>', dom.stdout, flags=re.DOTALL)
    if match is None:
        return ["the layout check did not run"]
    return list(json.loads(html.unescape(match[1])))


def main(argv: list[str]) -> int:
    site = Path(argv[0]) if argv else ROOT / "site"
    out = Path(argv[1]) if len(argv) > 1 else ROOT / "out" / "docs-screenshots"
    out.mkdir(parents=True, exist_ok=True)
    roles = raw_roles(site)
    for line in roles:
        print(line)
    failed = bool(roles)
    for name, (page, text) in PAGES.items():
        url = (site / page).resolve().as_uri()
        png = out / f"{name}.png"
        png.unlink(missing_ok=True)
        with tempfile.TemporaryDirectory() as profile:
            shot = chromium([f"--screenshot={png}", url], profile)
            dom = chromium(["--dump-dom", url], profile)
            found = [] if png.exists() else [f"no screenshot ({shot.stderr.strip()[-300:]})"]
            if text not in dom.stdout:
                found.append(f"the DOM does not hold {text!r}: an error page?")
            found += layout(site.resolve(), page, profile)
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
