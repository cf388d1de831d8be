"""The report is one self-contained page with a section per figure."""

from __future__ import annotations

import html
import json
import re

import numpy as np
import pytest

from tslip.plotting.report import SECTIONS, write_report
from tslip.sweeps import catalogue, run_study
from tslip.sweeps.claims import evaluate


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
    # every claim evaluated is on the page, with its verdict in claims.json
    assert claims and all(html.escape(c.text, quote=False) in text for c in claims)
    rows = json.loads((tmp_path / "claims.json").read_text())["claims"]
    assert [r["verdict"] for r in rows] == [c.verdict.value for c in claims]


def test_tiny_resolution() -> None:
    tiny = catalogue.studies("tiny")
    assert set(tiny) == set(catalogue.STUDIES)
    for name, spec in tiny.items():
        assert spec.n_points < catalogue.study(name, quick=True).n_points
        assert all(n == 3 for n in spec.shape if n > 1)  # a one-value axis is held
    assert catalogue.studies(True)["velocity"].n_points == catalogue.QUICK_LINE
    with pytest.raises(ValueError, match="resolution must be one of"):
        catalogue.studies("huge")


def test_appendix_e_cache_key_covers_the_biped():
    from tslip._codehash import module_closure
    from tslip.sweeps.reproduce import APPENDIX_E_MODULES

    closure = module_closure(*APPENDIX_E_MODULES)
    assert {"tslip.biped.simulate", "tslip.biped._kernels", "tslip.biped.gait"} <= set(closure)
    assert "tslip.sweeps.catalogue" not in closure  # a TSLIP study edit keeps it cached


def test_reproduce_end_to_end_tiny(tmp_path, monkeypatch) -> None:
    import json

    from tslip.biped import BipedParams
    from tslip.biped.simulate import default_min_contact
    from tslip.sweeps import appendix_e
    from tslip.sweeps.claims import CLAIMS, Verdict
    from tslip.sweeps.reproduce import APPENDIX_E_SETTINGS, appendix_e_cached, run_all

    data, claims, seconds = run_all(tmp_path, resolution="tiny", workers=1)
    assert data["quick"] is True and data["resolution"] == "tiny"
    assert set(catalogue.STUDIES) <= set(data)
    # 3 points a swept axis (an axis with one value is held)
    assert all(data[n].spec.n_points == 3 ** sum(len(a.values) > 1 for a in data[n].spec.axes)
               for n in catalogue.STUDIES)
    # every claim evaluated, each with a verdict
    assert len(claims) == len(CLAIMS)
    assert all(isinstance(c.verdict, Verdict) for c in claims)
    assert not [c for c in claims if c.error], [c.error for c in claims if c.error]

    # the evidence the claims are coded against
    t61 = data["table6.1"]
    variants = t61["pitch_rate_variants"]
    assert variants["touchdown, -"] == t61["pitch_rate"]
    assert all(v < 0 for k, v in variants.items() if ", -" in k)
    assert all(v > 0 for k, v in variants.items() if ", +" in k)
    forced = t61["alphad_ref_forced"]
    assert forced["alphad_ref"] == 2.42 and forced["free"] == t61["alphad_ref"]
    assert 0 < forced["residual"] < 1 and forced["c1"] >= forced["residual"] ** 2
    e2 = data["E"]["e2"]
    assert e2["min_contact"] == default_min_contact(BipedParams())
    assert 0 < e2["strides"] <= e2["strides_raw"]
    n_pert = APPENDIX_E_SETTINGS["tiny"]["n_random"]
    assert len(e2["strides_perturbed"]) == n_pert
    assert all(isinstance(n, int) for n in e2["strides_perturbed"])

    # the report
    path = write_report(tmp_path / "index.html", data, claims, quick=data["quick"],
                        seconds=seconds)
    assert path.is_file() and "<html" in path.read_text().lower()

    # a rerun takes Appendix E from the cache written by the first run
    monkeypatch.setattr(appendix_e, "fig_appendix_e", lambda **kw: pytest.fail("recomputed"))
    assert appendix_e_cached(tmp_path, "tiny")["e2"]["strides_perturbed"] == \
        e2["strides_perturbed"]

    # a rerun into the same folder takes every figure from the folder (none computed),
    # starts no worker process even when asked for two, and judges every claim as the
    # first run did
    from _same import same
    from tslip.sweeps import _pool, reproduce

    def never(*args: object, **kwargs: object) -> None:
        pytest.fail(f"computed again or a pool started: {args}")

    monkeypatch.setattr(reproduce, "_figure_task", never)
    monkeypatch.setattr(reproduce, "_table61_task", never)
    monkeypatch.setattr(_pool, "prestart", never)
    monkeypatch.setattr(_pool, "process_pool", never)
    again, claims_again, _ = run_all(tmp_path, resolution="tiny", workers=2)
    for key in [*reproduce._figure_jobs("tiny"), "table6.1", "E"]:
        same(data[key], again[key], key)
    assert [(c.verdict, repr(c.numbers), repr(c.evidence)) for c in claims_again] == \
        [(c.verdict, repr(c.numbers), repr(c.evidence)) for c in claims]

    doc = json.loads((tmp_path / "claims.json").read_text())
    assert doc["schema"] == 2
    rows = doc["claims"]
    assert len(rows) == len(claims)
    assert all("verdict" in r and "evidence" in r for r in rows)


#: Table E.2 as printed (positions, then velocities, STATE_FIELDS order).
TABLE_E2_PRINTED = ("0.000", "0.514", "-0.290", "0.700", "0.300", "-0.351", "0.370", "0.300",
                    "0.690", "1.898", "-0.079", "0.202", "-0.012", "-0.886", "1.6282", "-0.997",
                    "-0.136", "-2.9350")


def test_table_e2_perturbations_stay_within_the_printed_rounding() -> None:
    from tslip.biped import BipedState
    from tslip.sweeps.appendix_e import table_e2_perturbations

    y = BipedState.thesis().to_array()
    np.testing.assert_array_equal(y, [float(v) for v in TABLE_E2_PRINTED])
    half = np.array([0.5 * 10.0 ** -len(v.split(".")[1]) for v in TABLE_E2_PRINTED])
    rows = table_e2_perturbations(n_random=5, seed=1, one_at_a_time=True)
    assert rows.shape == (2 * 17 + 5, 18)
    d = rows - y
    # one at a time: entry i (x_b excepted) moved by -half, then +half
    for k in range(34):
        i = 1 + k // 2
        expected = np.zeros(18)
        expected[i] = (-1 if k % 2 == 0 else 1) * half[i]
        np.testing.assert_allclose(d[k], expected, atol=1e-15)
    # corners: every entry but x_b at +-half, reproducible by seed
    np.testing.assert_allclose(np.abs(d[34:, 1:]), np.broadcast_to(half[1:], (5, 17)),
                               rtol=1e-9)
    assert np.all(d[34:, 0] == 0)
    np.testing.assert_array_equal(rows, table_e2_perturbations(5, seed=1))
    assert table_e2_perturbations(0, one_at_a_time=False).shape == (0, 18)
