"""The repository holds code, tests and docs text only: no tracked file over 300 KB.

A session's whole submission was once rejected for its size (generated data had been
committed). Data a test or the docs need is generated at run time (CONTRIBUTING.md).
The largest tracked file today is about 40 KB.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LIMIT = 300_000  # bytes


def _tracked() -> list[Path]:
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("not a git checkout (an sdist); the check runs in CI's clone")
    out = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, check=True,
                         capture_output=True).stdout
    return [ROOT / name for name in out.decode().split("\0") if name]


def test_no_tracked_file_is_large() -> None:
    files = _tracked()
    assert len(files) > 100  # the listing worked
    big = {str(f.relative_to(ROOT)): f.stat().st_size for f in files
           if f.exists() and f.stat().st_size > LIMIT}
    assert not big, f"tracked files over {LIMIT} bytes (generate them instead): {big}"
