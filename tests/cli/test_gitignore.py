"""Every default output folder of a ``tslip`` command is ignored by git (issue 40: the
docs' own commands left ``?? designs/`` and ``?? viability/``)."""

import re
from pathlib import Path

import tslip

ROOT = Path(__file__).resolve().parents[2]
CLI = Path(tslip.__file__).parent / "cli"


def test_default_output_folders_are_in_gitignore():
    ignored = {line.strip() for line in (ROOT / ".gitignore").read_text().splitlines()}
    # defaults are written Path("name") (a folder) or Path("name") / spec.name
    defaults = {m for f in CLI.glob("*.py")
                for m in re.findall(r'Path\("([A-Za-z_]+)"\)', f.read_text())}
    assert {"studies", "viability", "designs", "report"} <= defaults
    assert not {f"/{d}/" for d in defaults} - ignored
