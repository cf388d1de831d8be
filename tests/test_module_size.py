"""No module of the package is over 600 lines without saying why it is one concept.

CONTRIBUTING.md: modules are one concept each and new ones stay under 600 lines. A module
over the limit carries, in its module docstring, a paragraph of its own that starts with
``Over 600 lines:`` and gives the reason in a sentence (issue 42). There is no list of
exempt files: a module that grows past the limit fails here until it is split or says why.
"""

import ast
from pathlib import Path

import pytest

#: The checkout's files, not the installed package's (CI installs a copy in site-packages).
ROOT = Path(__file__).resolve().parents[1] / "src" / "tslip"
LIMIT = 600
MARKER = "Over 600 lines:"


def _lines(path: Path) -> int:
    """Lines as ``wc -l`` counts them."""
    return path.read_bytes().count(b"\n")


def reason(source: str) -> str | None:
    """The reason a module's docstring gives for its length, or None: the text after
    ``Over 600 lines:`` on a docstring line that starts with it, at least five words."""
    doc = ast.get_docstring(ast.parse(source)) or ""
    for line in doc.splitlines():
        if line.startswith(MARKER):
            text = line[len(MARKER):].strip()
            return text if len(text.split()) >= 5 else None
    return None


def test_every_module_over_600_lines_says_why_it_is_one_concept() -> None:
    modules = sorted(ROOT.rglob("*.py"))
    assert len(modules) > 100  # the scan found the package
    long = {p.relative_to(ROOT).as_posix(): _lines(p) for p in modules if _lines(p) > LIMIT}
    missing = {m: n for m, n in long.items() if reason((ROOT / m).read_text()) is None}
    assert not missing, (f"modules over {LIMIT} lines (lines shown) whose docstring has no "
                         f"line starting {MARKER!r} and a reason: split them or say why they "
                         f"are one concept: {missing}")


@pytest.mark.parametrize(("source", "ok"), [
    ('"""Title.\n\nOver 600 lines: one concept, the stride and its drivers alike."""', True),
    ('"""Title.\n\nOver 600 lines:"""', False),                      # no reason
    ('"""Title.\n\nOver 600 lines: long."""', False),                # not a sentence
    ('"""Title. Over 600 lines: one concept, the stride and its drivers."""', False),  # not a line
    ('# Over 600 lines: one concept, the stride and its drivers alike.\nx = 1\n', False),
    ('x = 1\n"""Over 600 lines: one concept, a string that is not the docstring."""', False),
])
def test_the_reason_is_a_docstring_line_of_its_own(source: str, ok: bool) -> None:
    assert (reason(source) is not None) == ok
