"""Tests of an optional extra: skipped where it is not installed, failed in CI.

CI (``.ci/run``) sets ``TSLIP_REQUIRE_EXTRAS=1``: there the test extra installs every
optional extra, so a missing one is an installation fault, and its tests must fail
rather than skip in silence (as ``TSLIP_REQUIRE_BROWSER`` does for the browser tests).
"""

from __future__ import annotations

import importlib
import os
from types import ModuleType

import pytest

#: The environment variable under which a missing extra fails its tests.
REQUIRE = "TSLIP_REQUIRE_EXTRAS"


def require(module: str, extra: str) -> ModuleType:
    """``module`` imported; else the calling test module is skipped, or fails under CI."""
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        why = f"{module} is not installed (pip install 'tslip[{extra}]'): {exc}"
        if os.environ.get(REQUIRE) == "1":
            pytest.fail(f"{why}; {REQUIRE}=1 requires it", pytrace=False)
        pytest.skip(why, allow_module_level=True)
