"""A hanging test fails by timeout, so CI fails in minutes (issue 40, section 6).

pytest-timeout comes with the test extras and ``[tool.pytest.ini_options]`` sets a default
``timeout`` for every test (its comment says why that number). A test that never returns,
such as a search that never advances, then fails as "Timeout" instead of holding CI.
"""

import subprocess
import sys
import tomllib
from pathlib import Path

PYPROJECT = Path(__file__).resolve().parent.parent / "pyproject.toml"


def test_every_test_has_a_default_timeout(request):
    conf = tomllib.loads(PYPROJECT.read_text())
    default = float(conf["tool"]["pytest"]["ini_options"]["timeout"])
    assert 60 <= default <= 3600
    test_extras = conf["project"]["optional-dependencies"]["test"]
    assert any(r.startswith("pytest-timeout") for r in test_extras)
    assert float(request.config.getini("timeout")) == default  # this run's, unless overridden


def test_a_hanging_test_fails_by_timeout(tmp_path):
    """A test sleeping for 120 s, run with the project's configuration at a 2-s timeout."""
    test = tmp_path / "test_hang.py"
    test.write_text("import time\n\n\ndef test_hang():\n    time.sleep(120)\n")
    run = subprocess.run(
        [sys.executable, "-m", "pytest", "-c", str(PYPROJECT), "--rootdir", str(tmp_path),
         "-p", "no:cacheprovider", "-o", "timeout=2", str(test)],
        capture_output=True, text=True, timeout=100, cwd=tmp_path)
    assert run.returncode == 1, run.stdout + run.stderr
    assert "Timeout" in run.stdout and "1 failed" in run.stdout
