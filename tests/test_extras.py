"""A test module of a missing optional extra skips locally and fails in CI (tests/_extras.py)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parent

MODULE = '''
from _extras import require

require("tslip_no_such_extra_module", "nothing")


def test_never_runs():
    pass
'''


@pytest.mark.parametrize(("required", "code", "said"), [
    ("", 0, "1 passed, 1 skipped"),
    ("1", 2, "tslip_no_such_extra_module is not installed (pip install 'tslip[nothing]')")])
def test_a_missing_extra_skips_or_fails(tmp_path, required, code, said):
    (tmp_path / "test_x.py").write_text(MODULE)
    (tmp_path / "test_ok.py").write_text("def test_ok():\n    pass\n")
    env = {**os.environ, "TSLIP_REQUIRE_EXTRAS": required,
           "PYTHONPATH": os.pathsep.join([str(TESTS), os.environ.get("PYTHONPATH", "")])}
    res = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                          "-rs", str(tmp_path)], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=120)
    assert res.returncode == code, res.stdout + res.stderr
    assert said in res.stdout


def test_ci_requires_the_extras():
    ci = (TESTS.parent / ".ci" / "run").read_text()
    assert "\nexport TSLIP_REQUIRE_EXTRAS=1\n" in ci
