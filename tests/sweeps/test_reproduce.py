"""The report is one self-contained page with a section per figure."""

from __future__ import annotations

import re

import pytest

from tslip.plotting.report import SECTIONS, write_report
from tslip.sweeps import catalogue, run_study
from tslip.sweeps.claims import evaluate

pytestmark = pytest.mark.filterwarnings("ignore::RuntimeWarning")


def test_catalogue_resolutions() -> None:
    for s in catalogue.STUDIES.values():
        full, quick = s.at(False), s.at(True)
        swept = [n for n in full.shape if n > 1]  # an axis with one value is held
        assert all(n >= 40 for n in swept) and all(n >= 50 for n in swept[:1]
                                                   if len(swept) == 1)
        assert quick.n_points < full.n_points
    assert catalogue.study("stiffness").axes[0].values[0] > 0  # k > 0


def test_report_is_self_contained(tmp_path) -> None:
    data = {"mass_offset": run_study(catalogue.study("mass_offset", quick=True), workers=1),
            "4.1": catalogue.fig_impulse_linearisation(),
            "C.1": catalogue.fig_friction()}
    claims = evaluate(data)
    path = write_report(tmp_path / "index.html", data, claims, quick=True)
    text = path.read_text()
    assert "http://" not in text and "https://" not in text
    imgs = re.findall(r"<img [^>]*src='([^']*)'", text)
    assert len(imgs) >= 4 and all(s.startswith("data:image/png;base64,") for s in imgs)
    for figs, _ in SECTIONS:
        assert f"id='fig-{figs[0].replace('.', '-')}'" in text
    assert "does not hold" in text or all(c.holds for c in claims)
    assert (tmp_path / "claims.json").exists()
