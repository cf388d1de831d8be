"""The integrator loops stay readable: no function of the simulator grades worse than C.

Issue 25 asked for the TSLIP stride (``simulation/_stride.py``) and the biped's
integrator (``biped/_stride.py``) to read as a few named steps (step, error
control, event detection, event location, dense output) instead of one loop of
cyclomatic complexity 59 and 56. Radon's grade C is a complexity of at most 20.
Issue 41 extended the check to every module of ``simulation/`` (a glob, so a new
module is covered without editing this file), closures at any depth included.
The 3-D TSLIP's phase loop and stride (issue 43) are graded too.
The files are read from the checkout, as CONTRIBUTING's file-map test does.
"""

from pathlib import Path

import pytest
from radon.complexity import cc_rank, cc_visit

SRC = Path(__file__).resolve().parents[1] / "src" / "tslip"
KERNELS = sorted(f.relative_to(SRC).as_posix() for f in (SRC / "simulation").glob("*.py"))
KERNELS += ["biped/_stride.py", "spatial/_trunk_kernels.py", "spatial/_trunk_stride.py"]


def _closures(block):
    for inner in getattr(block, "closures", []):
        yield inner
        yield from _closures(inner)


def _blocks(path: Path):
    for block in cc_visit(path.read_text()):
        yield block
        yield from _closures(block)


def test_every_simulation_module_is_graded() -> None:
    """The glob finds the simulator's modules (an empty or wrong folder would pass vacuously)."""
    for name in ("simulation/_stride.py", "simulation/_flight.py", "simulation/integrate.py",
                 "simulation/_variational.py", "biped/_stride.py", "spatial/_trunk_stride.py"):
        assert name in KERNELS
    assert all((SRC / name).is_file() for name in KERNELS)


@pytest.mark.parametrize("name", KERNELS)
def test_kernel_functions_grade_c_or_better(name: str) -> None:
    worse = [f"{b.name} (line {b.lineno}): {b.complexity} ({cc_rank(b.complexity)})"
             for b in _blocks(SRC / name) if cc_rank(b.complexity) > "C"]
    assert not worse, f"{name}: " + "; ".join(worse)


def test_the_grading_sees_a_complex_closure(tmp_path: Path) -> None:
    """The check itself: a closure with 21 branches inside a factory, and one a level deeper,
    are found and graded D (complexity 22)."""
    body = "\n".join(f"        if x == {i}:\n            x += 1" for i in range(21))
    src = f"def make():\n    def inner(x):\n{body}\n        return x\n    return inner\n"
    deeper = "def outer():\n" + "".join(f"    {line}\n" for line in src.splitlines())
    deeper += "    return make\n"
    for text in (src, deeper):
        f = tmp_path / "m.py"
        f.write_text(text)
        grades = {b.name: (b.complexity, cc_rank(b.complexity)) for b in _blocks(f)}
        assert grades["inner"] == (22, "D")
