"""The first run: it says which kernel families it compiles, and compiles each once."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

from tslip import _kernel_cache as kc

_ANNOUNCE = textwrap.dedent("""
    import json, sys, time
    from tslip import _kernel_cache as kc
    from tslip.sweeps._warmup import announce
    print(json.dumps({k: str(v) for k, v in kc.cache_dirs().items()}), flush=True)
    if sys.argv[1] == "fabricate":
        sys.exit(0)
    with announce(lambda s: print("SAID " + s, flush=True)) as missing:
        pass
""")


def _run(cache: Path, mode: str) -> list[str]:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    out = subprocess.run([sys.executable, "-c", _ANNOUNCE, mode], env=env, text=True,
                         capture_output=True, timeout=120, check=True).stdout
    return out.splitlines()


def test_a_cold_cache_is_announced_and_a_warm_one_is_not(tmp_path):
    cold = _run(tmp_path, "announce")
    said = [s for s in cold if s.startswith("SAID ")]
    assert len(said) == 1 and "compiling 4 kernel families" in said[0]
    for name in kc.FAMILIES:
        assert name in said[0]
    # the same folders, as a warm cache (index files of every family's kernels)
    dirs = {k: Path(v) for k, v in json.loads(_run(tmp_path, "fabricate")[0]).items()}
    for package, kernels in kc.FAMILIES.values():
        dirs[package].mkdir(parents=True, exist_ok=True)
        for kernel in kernels:
            stem = kernel.split(".")[0]
            (dirs[package] / f"{stem}.tslip-sources").write_text(kc.sources_hash())
            (dirs[package] / f"{kernel}-12.py311.nbi").write_text("x")
    warm = _run(tmp_path, "announce")
    assert not [s for s in warm if s.startswith("SAID ")]
