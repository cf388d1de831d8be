"""Latency of ``tslip explore``: a slider move to the redrawn gait and multipliers (issue 27).

Starts ``tslip explore`` in a subprocess, opens it in the system Chromium
(Playwright), waits for the first gait (warm kernel cache: run once before to
fill it), then moves the ``k`` slider 20 times per preset. Each move is timed
in the page (``performance.now``): from setting the slider's value to the
frame in which both the new gait (its plot's data) and the new multipliers
(their text) are in the page's document, and on to the robustness limits (or
their "none" for an unstable gait). Prints the start-up time (launch to the
first HTTP 200), and per preset the median and p95 of both, with the 1-minute
load.

``--against SRC`` serves a second explorer from another source tree (e.g. an
older commit's ``src``, from ``git archive``) and alternates the moves between
the two pages, so both see the same load::

    git archive <commit> src | tar -x -C /tmp/old
    python benchmarks/bench_explore.py --against /tmp/old/src

Target (issue 27): p95 <= 0.3 s to the gait and multipliers, limits within 2 s,
serving within 10 s. Run by hand, never in CI::

    python benchmarks/bench_explore.py
"""

from __future__ import annotations

import argparse
import os
import shutil
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import numpy as np

MOVE = """
async ([v]) => {
  const d = Bokeh.documents[0];
  const src = d.get_model_by_name('gait_source'), lim = d.get_model_by_name('limits');
  const mult = d.get_model_by_name('multipliers');
  const oldx = src.data.x, oldm = mult.text;
  const until = (ok) => new Promise((res, rej) => {
    const t = performance.now();
    const f = () => ok() ? res() : (performance.now() - t > 20000 ? rej('timeout')
                                     : requestAnimationFrame(f));
    f(); });
  const t0 = performance.now();
  d.get_model_by_name('k').value = v;
  await until(() => src.data.x !== oldx && mult.text !== oldm);
  const t1 = performance.now();
  await until(() => !lim.text.includes('updating'));  // 'updating' comes with the gait
  return [t1 - t0, performance.now() - t0];
}
"""
READY = ("() => { const d = window.Bokeh && Bokeh.documents[0];"
         " const m = d && d.get_model_by_name('limits');"
         " return m && m.text.startsWith('robustness limits (25'); }")
SAYS = ("() => ['status', 'error', 'multipliers', 'limits'].map("
        "n => Bokeh.documents[0].get_model_by_name(n).text)")
PRESETS = (("table2.1", 25.0, 0.25), ("table6.1", 8.0, 0.05))


def start(src: str | None) -> tuple[subprocess.Popen[bytes], str, float]:
    """An explorer on a free port (``src``: its source tree, else this environment's)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    url = f"http://127.0.0.1:{port}/"
    env = os.environ.copy()
    if src is not None:
        env["PYTHONPATH"] = str(Path(src).resolve())
    t0 = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "tslip", "explore", "--port", str(port),
                             "--no-open"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            env=env)
    while True:
        try:
            with urllib.request.urlopen(url + "favicon.ico", timeout=2):  # noqa: S310
                return proc, url, time.perf_counter() - t0
        except OSError:
            if proc.poll() is not None:
                where = src or "this environment"
                raise RuntimeError(f"the explorer from {where} exited") from None
            time.sleep(0.05)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--against", metavar="SRC", help="also serve this source tree and "
                    "alternate the moves between the two")
    ap.add_argument("--moves", type=int, default=20)
    args = ap.parse_args()
    from playwright.sync_api import sync_playwright

    variants = {"this": None} if args.against is None else {"this": None, "against": args.against}
    servers = {}
    try:
        for name, src in variants.items():
            proc, url, secs = start(src)
            servers[name] = (proc, url)
            print(f"{name}: serving after {secs:.2f} s (1-min load {os.getloadavg()[0]:.1f})")
        with sync_playwright() as p:
            b = p.chromium.launch(executable_path=shutil.which("chromium"), args=["--no-sandbox"])
            pages = {name: b.new_page(viewport={"width": 1300, "height": 1500})
                     for name in servers}
            for preset, k0, dk in PRESETS:
                for name, page in pages.items():
                    page.goto(f"{servers[name][1]}?preset={preset}")
                    try:
                        page.wait_for_function(READY, timeout=180_000)
                    except Exception:
                        print(f"{name}: the first gait's limits did not come; the page says",
                              page.evaluate(SAYS))
                        raise
                gait: dict[str, list[float]] = {n: [] for n in pages}
                limits: dict[str, list[float]] = {n: [] for n in pages}
                for i in range(args.moves):
                    v = k0 + dk * (i // 2 + 1) * (-1) ** i
                    order = list(pages) if i % 2 == 0 else list(pages)[::-1]
                    for name in order:
                        a, c = pages[name].evaluate(MOVE, [v])
                        gait[name].append(a / 1e3)
                        limits[name].append(c / 1e3)
                for name in pages:
                    g, lim = np.array(gait[name]), np.array(limits[name])
                    print(f"{name} {preset}: slider -> gait and multipliers median "
                          f"{np.median(g):.3f} s, p95 {np.percentile(g, 95):.3f} s; -> limits "
                          f"median {np.median(lim):.3f} s, p95 {np.percentile(lim, 95):.3f} s "
                          f"(1-min load {os.getloadavg()[0]:.1f})")
            b.close()
    finally:
        for proc, _ in servers.values():
            proc.terminate()
            proc.wait(timeout=10)


if __name__ == "__main__":
    main()
