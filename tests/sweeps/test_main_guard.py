"""Workers are spawned and import the main script again: an unguarded script is refused."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

_POOL = "from tslip.sweeps._pool import process_pool\n"


def _run(tmp_path: Path, body: str) -> subprocess.CompletedProcess[str]:
    script = tmp_path / "script.py"
    script.write_text(_POOL + body)
    return subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                          timeout=300, cwd=tmp_path)


def test_unguarded_script_is_refused_in_one_line(tmp_path: Path) -> None:
    res = _run(tmp_path, "with process_pool(2) as pool:\n"
                         "    print(pool.submit(abs, -3).result())\n")
    assert res.returncode != 0
    last = res.stderr.strip().splitlines()[-1]
    assert last.startswith("RuntimeError: worker processes import the script")
    assert 'if __name__ == "__main__":' in last and "workers=1" in last
    assert "BrokenProcessPool" not in res.stderr


@pytest.mark.parametrize("guard", ['__name__ == "__main__"', "'__main__' == __name__"])
def test_guarded_script_runs_its_workers(tmp_path: Path, guard: str) -> None:
    res = _run(tmp_path, f"if {guard}:\n    with process_pool(2) as pool:\n"
                         "        print(pool.submit(abs, -3).result())\n")
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip() == "3"
