"""``import tslip`` is cheap: the public names load on first use (PEP 562).

Checked by which modules a fresh interpreter has loaded, never by timing
(``benchmarks/bench_coldstart.py`` times it).
"""

import ast
import json
import subprocess
import sys
import types
from pathlib import Path

import pytest

import tslip

#: Heavy or compiled modules that ``import tslip`` must not load.
HEAVY = ("pandas", "pyarrow", "scipy.optimize", "matplotlib", "numba",
         "tslip.simulation._kernels", "tslip.simulation._variational", "tslip.simulation._rk",
         "tslip.biped._kernels", "tslip.gait")

_LOADED = """
import json, sys
{code}
print(json.dumps(sorted(sys.modules)))
"""


def _loaded_after(code: str) -> set[str]:
    out = subprocess.run([sys.executable, "-c", _LOADED.format(code=code)], capture_output=True,
                         text=True, check=True)
    return set(json.loads(out.stdout.strip().splitlines()[-1]))


def _static_imports(package: types.ModuleType) -> dict[str, str]:
    """A package's relative ``from .module import name`` lines (its ``TYPE_CHECKING``
    block): name -> module."""
    tree = ast.parse(Path(package.__file__ or "").read_text(encoding="utf-8"))
    return {a.name: node.module or "" for node in ast.walk(tree)
            if isinstance(node, ast.ImportFrom) and node.level == 1 for a in node.names}

def test_import_tslip_loads_no_heavy_module():
    loaded = _loaded_after("import tslip")
    assert not loaded & set(HEAVY), loaded & set(HEAVY)


def test_first_stride_loads_only_what_it_uses():
    loaded = _loaded_after("import tslip\n"
                           "tslip.step_map(tslip.preset('table2.1'), [1.05, 0, 5, -0.3, 0])")
    assert "tslip.simulation._kernels" in loaded  # the check above can see kernels
    unused = {"pandas", "pyarrow", "scipy.optimize", "matplotlib", "tslip.gait",
              "tslip.simulation._variational", "tslip.biped._kernels"}
    assert not loaded & unused, loaded & unused


def test_public_names_are_listed_and_resolve():
    assert set(tslip.__all__) <= set(dir(tslip))
    ns: dict = {}
    exec("from tslip import *", ns)
    assert set(tslip.__all__) <= set(ns)
    assert ns["simulate"] is tslip.simulation.simulate and ns["Gait"] is tslip.gait.Gait
    assert tslip.preset is tslip.model.preset


def test_lazy_table_matches_the_static_imports():
    """The name -> subpackage table is the ``TYPE_CHECKING`` imports (what type checkers see)."""
    static = _static_imports(tslip)
    assert static == tslip._SUBPACKAGE
    assert set(static) | {"__version__"} == set(tslip.__all__)


def test_unknown_attribute_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no_such_name"):
        tslip.no_such_name  # noqa: B018


def test_a_planar_study_loads_no_3d_gait_search():
    """``import tslip.sweeps`` (every command and worker imports it) registers the 3-D
    models without loading their gait searches: those load for a 3-D study only."""
    loaded = _loaded_after("import tslip.sweeps")
    assert "tslip.sweeps.run" in loaded  # the check above can see the study code
    heavy = {"tslip.spatial.gait", "tslip.spatial.lateral", "tslip.spatial.trunk_section",
             "tslip.sweeps.spatial_point"}
    assert not loaded & heavy, loaded & heavy


def test_the_study_code_loads_scipy_optimize_only_when_it_solves():
    """``scipy.optimize`` (0.2-0.5 s to import) loads with the first least-squares gait
    search, root bracket or impulse quadrature (``scipy.integrate`` imports it), not with
    ``import tslip.sweeps`` and the report (every command, every warm rerun)."""
    loaded = _loaded_after("import tslip.sweeps, tslip.sweeps.reproduce, tslip.gait.impulse")
    assert "scipy.linalg" in loaded  # the check above can see scipy (Floquet needs LAPACK)
    assert not {"scipy.optimize", "scipy.integrate"} & loaded
    solved = _loaded_after("import numpy as np; from tslip.gait.impulse import _simpson; "
                           "_simpson(np.ones(3), np.arange(3.0))")
    assert "scipy.optimize" in solved


def test_the_report_loads_matplotlib_only_to_draw():
    """``tslip reproduce`` imports the report module; matplotlib (about 0.6 s) loads only
    when a figure is drawn, never for a rerun whose figures are all in the folder."""
    loaded = _loaded_after("import tslip.plotting.report, tslip.cli.studies")
    assert "tslip.plotting.report" in loaded
    assert not {m for m in loaded if m.split(".")[0] in ("matplotlib", "PIL")}
    drawn = _loaded_after("import tslip.plotting; tslip.plotting.plot_trajectory")
    assert "matplotlib.figure" in drawn


def test_the_plotting_names_are_its_modules_names():
    """``tslip.plotting``'s lazy table is its ``TYPE_CHECKING`` imports, and each name is
    the function of that module."""
    import importlib

    import tslip.plotting as plotting

    static = _static_imports(plotting)
    assert static == plotting._LAZY
    assert set(static) == set(plotting.__all__) <= set(dir(plotting))
    for name, module in static.items():
        assert getattr(plotting, name) is getattr(
            importlib.import_module(f"tslip.plotting.{module}"), name)
    with pytest.raises(AttributeError, match="no_such_plot"):
        plotting.no_such_plot  # noqa: B018
