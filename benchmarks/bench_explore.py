"""Latency of ``tslip explore``: a slider move to the redrawn gait and multipliers (issue 27).

Starts ``tslip explore`` in a subprocess, opens it in the system Chromium
(Playwright), waits for the first gait (warm kernel cache: run once before to
fill it), then moves the ``k`` slider 20 times per preset. Each move is timed
in the page (``performance.now``): from setting the slider's value to the
frame in which the new gait and multipliers are in the page's document, and on
to the robustness limits (or their "none" for an unstable gait). Prints the
start-up time (launch to the first HTTP 200), and per preset the median and p95
of both.

Target (issue 27): p95 <= 0.3 s to the gait and multipliers, limits within 2 s,
serving within 10 s. Run by hand, never in CI::

    python benchmarks/bench_explore.py
"""

from __future__ import annotations

import os
import shutil
import socket
import subprocess
import sys
import time
import urllib.request

import numpy as np

MOVE = """
async ([v]) => {
  const d = Bokeh.documents[0];
  const src = d.get_model_by_name('gait_source'), lim = d.get_model_by_name('limits');
  const oldx = src.data.x;
  const until = (ok) => new Promise((res, rej) => {
    const t = performance.now();
    const f = () => ok() ? res() : (performance.now() - t > 20000 ? rej('timeout')
                                     : requestAnimationFrame(f));
    f(); });
  const t0 = performance.now();
  d.get_model_by_name('k').value = v;
  await until(() => src.data.x !== oldx);
  const t1 = performance.now();
  await until(() => !lim.text.includes('updating'));  // 'updating' comes before the gait
  return [t1 - t0, performance.now() - t0];
}
"""


def main() -> None:
    from playwright.sync_api import sync_playwright

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    url = f"http://127.0.0.1:{port}/"
    t0 = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "tslip", "explore", "--port", str(port),
                             "--no-open"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            env=os.environ.copy())
    try:
        while True:
            try:
                with urllib.request.urlopen(url + "favicon.ico", timeout=2):  # noqa: S310
                    break
            except OSError:
                time.sleep(0.05)
        print(f"serving after {time.perf_counter() - t0:.2f} s "
              f"(1-min load {os.getloadavg()[0]:.1f})")
        with sync_playwright() as p:
            b = p.chromium.launch(executable_path=shutil.which("chromium"), args=["--no-sandbox"])
            page = b.new_page(viewport={"width": 1300, "height": 1500})
            for name, k0, dk in (("table2.1", 25.0, 0.25), ("table6.1", 8.0, 0.05)):
                page.goto(f"{url}?preset={name}")
                page.wait_for_function(
                    "() => { const d = window.Bokeh && Bokeh.documents[0];"
                    " const m = d && d.get_model_by_name('limits');"
                    " return m && m.text.startsWith('robustness limits (25'); }",
                    timeout=180_000)
                gait, limits = [], []
                for i in range(20):
                    v = k0 + dk * (i // 2 + 1) * (-1) ** i
                    a, c = page.evaluate(MOVE, [v])
                    gait.append(a / 1e3)
                    limits.append(c / 1e3)
                g, lim = np.array(gait), np.array(limits)
                print(f"{name}: slider -> gait and multipliers median {np.median(g):.3f} s, "
                      f"p95 {np.percentile(g, 95):.3f} s; -> limits median "
                      f"{np.median(lim):.3f} s, p95 {np.percentile(lim, 95):.3f} s "
                      f"(1-min load {os.getloadavg()[0]:.1f})")
            b.close()
    finally:
        proc.terminate()
        proc.wait(timeout=10)


if __name__ == "__main__":
    main()
