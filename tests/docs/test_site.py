"""The documentation site: built with warnings as errors, then opened in headless Chromium.

The build runs the gallery (every example executes) and the reproduction behind the
verdict table, at the ``tiny`` resolution to keep the suite short. The pages are then
served on localhost and loaded by a real browser, which reports what it rendered: the
page titles, the navigation, the gallery's thumbnails, and whether every image loaded.

Chromium is a system package (``apt-get install chromium``); ``.ci/run`` installs it and
sets ``TSLIP_REQUIRE_BROWSER=1``, under which a missing browser fails the test instead of
skipping it.
"""

from __future__ import annotations

import functools
import http.server
import json
import os
import re
import shutil
import subprocess
import sys
import threading
from collections.abc import Iterator
from html import unescape
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
EXAMPLES = sorted((ROOT / "examples").glob("plot_*.py"))
ANALYSES = ("gait", "stability", "slip", "robustness", "impulse", "stride", "studies", "experiment",
            "biped", "spatial", "spatial_tslip")


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Build the site once; fail on any warning."""
    out = tmp_path_factory.mktemp("site") / "html"
    env = dict(os.environ, TSLIP_DOCS_RESOLUTION="tiny", MPLBACKEND="agg")
    proc = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html", str(DOCS),
         str(out)], capture_output=True, text=True, env=env, cwd=ROOT)
    warnings = [ln for ln in proc.stderr.splitlines() if "WARNING" in ln or "ERROR" in ln]
    assert proc.returncode == 0 and not warnings, "\n".join(warnings) or proc.stderr[-3000:]
    return out


def test_every_page_is_built(site: Path) -> None:
    pages = ["index", "getting-started", "model", "conventions", "reproducing", "speed",
             "changelog", "_generated/cli", "api/index", "gallery/index",
             *(f"analyses/{a}" for a in ANALYSES),
             *(f"api/{m}" for m in ("model", "simulation", "gait", "sweeps", "biped", "spatial",
                                    "experiment", "plotting", "protocols")),
             *(f"gallery/{e.stem}" for e in EXAMPLES)]
    missing = [p for p in pages if not (site / f"{p}.html").is_file()]
    assert not missing
    assert len(EXAMPLES) >= 10
    assert (site / "report" / "index.html").is_file()


def _figures_made(script: Path) -> int:
    """The figures an example makes, read from its source: each ``plt.figure`` or
    ``plt.subplots`` call, and each call of a ``tslip.plotting`` function or of a
    result's ``.plot()`` whose result (a Figure) is bound to a name; a plotting function
    given ``ax=`` draws into a figure already counted."""
    import ast

    tree = ast.parse(script.read_text())
    plotting = {a.asname or a.name for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)
                and (node.module or "").startswith("tslip.plotting") for a in node.names}
    n = 0
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) \
                and isinstance(node.func.value, ast.Name) and node.func.value.id == "plt":
            n += node.func.attr in ("figure", "subplots")
        elif isinstance(node, ast.Assign) and isinstance(node.value, ast.Call) \
                and isinstance(node.value.func, ast.Name):
            n += node.value.func.id in plotting
        elif isinstance(node, ast.Assign) and isinstance(node.value, ast.Call) \
                and isinstance(node.value.func, ast.Attribute) \
                and node.value.func.attr == "plot" \
                and not any(k.arg == "ax" for k in node.value.keywords):
            n += 1  # a result's .plot() (a new Figure) bound to a name
    return n


def test_each_gallery_page_shows_each_figure_once(site: Path) -> None:
    """A page has one image per figure its script makes: none missing, none saved twice
    (by both the matplotlib scraper and ``tslip_docs.figure_scraper``)."""
    for example in EXAMPLES:
        page = (site / "gallery" / f"{example.stem}.html").read_text()
        images = re.findall(r'<img [^>]*class\s*=\s*"sphx-glr-(?:single|multi)-img"', page)
        made = _figures_made(example)
        assert made >= 1, example.name
        assert len(images) == made, f"{example.name}: {len(images)} images, {made} figures"


def test_generated_pages_follow_the_code(site: Path) -> None:
    """The CLI reference lists every command; the parameter table every field."""
    import dataclasses

    import typer

    from tslip.cli.main import app
    from tslip.model import Params

    cli = unescape(re.sub(r"<[^>]+>", "", (site / "_generated" / "cli.html").read_text()))
    root = typer.main.get_command(app)
    ctx = root.context_class(root, info_name="tslip")
    for name in root.list_commands(ctx):
        assert f"tslip {name}" in cli, name
    model = unescape(re.sub(r"<[^>]+>", "", (site / "model.html").read_text()))
    for f in dataclasses.fields(Params):
        if "unit" in f.metadata:
            default = "None" if f.default is None else f"{f.default:g}"
            row = re.search(rf"\n{re.escape(f.name)}\n{re.escape(f.metadata['symbol'])}\n"
                            rf"{re.escape(f.metadata['unit'])}\n{default}\n", model)
            assert row, f"parameter {f.name} missing or wrong in the table"


def test_verdict_table_counts_every_claim(site: Path) -> None:
    from tslip.sweeps.claims import CLAIMS

    text = unescape(re.sub(r"<[^>]+>", "", (site / "reproducing.html").read_text()))
    m = re.search(r"(\d+) claims at tiny resolution", text)
    assert m and int(m.group(1)) == len(CLAIMS)


# -- the browser -------------------------------------------------------------------

_CHECK = """<!DOCTYPE html><html><body><pre id="result">pending</pre><script>
const pages = %s;
const out = {};
function inspect(i) {
  if (i === pages.length) {
    document.getElementById("result").textContent = JSON.stringify(out);
    return;
  }
  const frame = document.createElement("iframe");
  frame.src = pages[i];
  frame.onload = () => {
    const doc = frame.contentDocument;
    const imgs = Array.from(doc.images);
    out[pages[i]] = {
      title: doc.title,
      headings: Array.from(doc.querySelectorAll("h1")).map(h => h.textContent),
      nav: Array.from(doc.querySelectorAll(".sidebar-tree a")).map(a => a.textContent),
      thumbs: doc.querySelectorAll(".sphx-glr-thumbcontainer").length,
      images: imgs.length,
      loaded: imgs.filter(im => im.complete && im.naturalWidth > 0).length,
    };
    inspect(i + 1);
  };
  document.body.appendChild(frame);
}
inspect(0);
</script></body></html>"""


def _browser() -> str:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    msg = "no Chromium for the headless-browser test (apt-get install chromium)"
    if os.environ.get("TSLIP_REQUIRE_BROWSER") == "1":
        pytest.fail(msg)
    pytest.skip(msg)


@pytest.fixture(scope="module")
def served(site: Path) -> Iterator[str]:
    handler = functools.partial(_QuietHandler, directory=str(site))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}"
    finally:
        server.shutdown()
        server.server_close()


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args: object) -> None:
        pass


def _render(site: Path, url: str, pages: list[str], tmp_path: Path) -> dict:
    (site / "_check.html").write_text(_CHECK % json.dumps(pages))
    proc = subprocess.run(
        [_browser(), "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
         "--no-first-run", "--disable-background-networking", "--disable-component-update",
         "--disable-sync", f"--user-data-dir={tmp_path / 'profile'}",
         "--virtual-time-budget=20000", "--dump-dom", f"{url}/_check.html"],
        capture_output=True, text=True, timeout=120)
    m = re.search(r'<pre id="result">(.*?)</pre>', proc.stdout, re.S)
    assert m, proc.stdout[-2000:] + proc.stderr[-2000:]
    assert m.group(1) != "pending", "the browser did not finish loading the pages"
    return json.loads(unescape(m.group(1)))


def test_browser_opens_index_and_gallery(site: Path, served: str, tmp_path: Path) -> None:
    example = f"gallery/{EXAMPLES[0].stem}.html"
    got = _render(site, served, ["index.html", "gallery/index.html", example], tmp_path)
    index = got["index.html"]
    assert index["headings"] and index["headings"][0].strip().startswith("tslip")
    for entry in ("Getting started", "The model", "Analyses", "Examples",
                  "Reproducing the thesis", "Command-line reference", "API reference"):
        assert any(entry in n for n in index["nav"]), (entry, index["nav"])
    gallery = got["gallery/index.html"]
    assert gallery["thumbs"] == len(EXAMPLES)
    assert gallery["images"] >= len(EXAMPLES)
    for page, info in got.items():
        assert info["loaded"] == info["images"], f"{page}: broken images"
    assert got[example]["images"] >= 1  # the example's figure
