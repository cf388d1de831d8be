"""The integrator loops stay readable: no function in the stride kernels grades worse than C.

Issue 25 asked for the TSLIP stride (``simulation/_stride.py``) and the biped's
integrator (``biped/_stride.py``) to read as a few named steps (step, error
control, event detection, event location, dense output) instead of one loop of
cyclomatic complexity 59 and 56. Radon's grade C is a complexity of at most 20.
The files are read from the checkout, as CONTRIBUTING's file-map test does.
"""

from pathlib import Path

import pytest
from radon.complexity import cc_rank, cc_visit

SRC = Path(__file__).resolve().parents[1] / "src" / "tslip"
KERNELS = ["simulation/_stride.py", "biped/_stride.py"]


def _blocks(path: Path):
    for block in cc_visit(path.read_text()):
        yield block
        yield from getattr(block, "closures", [])


@pytest.mark.parametrize("name", KERNELS)
def test_kernel_functions_grade_c_or_better(name: str) -> None:
    worse = [f"{b.name} (line {b.lineno}): {b.complexity} ({cc_rank(b.complexity)})"
             for b in _blocks(SRC / name) if cc_rank(b.complexity) > "C"]
    assert not worse, f"{name}: " + "; ".join(worse)


def test_the_grading_sees_a_complex_closure() -> None:
    """The check itself: a closure with 21 branches inside a factory is found and graded D."""
    body = "\n".join(f"        if x == {i}:\n            x += 1" for i in range(21))
    src = f"def make():\n    def inner(x):\n{body}\n        return x\n    return inner\n"
    grades = {b.name: cc_rank(b.complexity) for b in cc_visit(src)
              for b in [b, *getattr(b, "closures", [])]}
    assert grades["inner"] == "D"
