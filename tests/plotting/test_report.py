"""The reproduce report a reviewer reads: labelled figures, three verdicts, working links.

Figures are built by the report's own plot table (``report._plots``) from
constructed study results (a synthetic frame per catalogue study, so every
axis the report draws exists) and the real single-gait analyses, which take
a second or two each.
"""

from __future__ import annotations

import itertools
import json
import re
from html.parser import HTMLParser
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
from matplotlib.collections import QuadMesh
from matplotlib.colors import to_rgba

from tslip.plotting import report
from tslip.sweeps import catalogue
from tslip.sweeps.claims import ClaimResult, Verdict
from tslip.sweeps.run import StudyResult

pytestmark = pytest.mark.filterwarnings("ignore::RuntimeWarning")

UNIT = re.compile(r"\[[^\[\]]+\]")  # a unit in brackets: "[L]", "[rad]", "[-]"


def _stable_code(i: int) -> int:
    """0 no gait, 1 unstable gait, 2 stable: cycles through all three."""
    return i % 3


def _study(name: str) -> StudyResult:
    """A catalogue study at quick resolution with a constructed result frame."""
    spec = catalogue.study(name, quick=True)
    pts = list(itertools.product(*(a.values for a in spec.axes)))
    n = len(pts)
    code = np.array([_stable_code(i) for i in range(n)])
    rows = {a.param: [p[j] for p in pts] for j, a in enumerate(spec.axes)}
    x = np.linspace(0.0, 1.0, n)
    frame = pd.DataFrame({
        **rows,
        "converged": code > 0,
        "stability": np.where(code == 2, "asymptotic", "unstable"),
        "max_nontrivial": np.where(code == 2, 0.5, 1.5),
        "n_trivial": np.ones(n, int),
        **{f"abs_lambda_{j}": 0.2 * j + 0.1 * x for j in range(1, 6)},
        "step_down": -0.1 - x, "push": -0.5 * x, "pitch_rate": -x,
        "stance_time": 0.5 + x, "stance_time_predicted": 0.5 + 1.1 * x,
        "flight_time": 0.2 + x, "flight_time_predicted": 0.2 + 0.9 * x,
        "residual": np.full(n, 1e-12),
    })
    return StudyResult(spec, frame, {"points": n, "computed": n, "seconds": 0.0})


def _height_change() -> dict:
    r = SimpleNamespace(dv=0.1, dv_expected=0.12)
    dh = (-0.1, 0.05)
    return {"dh": dh, "passive": [r, r], "local_velocity": [r, r]}


@pytest.fixture(scope="module")
def data() -> dict:
    out: dict = {name: _study(name) for name in catalogue.STUDIES}
    out.update({
        "4.1": catalogue.fig_impulse_linearisation(),
        "4.2": catalogue.fig_pitch_disturbance("table2.1"),
        "4.3": catalogue.fig_pitch_disturbance("table2.1-global-pd"),
        "6.2": catalogue.fig_pitch_disturbance("table6.1"),
        "4.4": _height_change(),
        "4.5": catalogue.fig_step_down(n_steps=6),
        "4.7": catalogue.fig_velocity_angle(),
        "C.1": catalogue.fig_friction(),
        "E": _appendix_e(),
    })
    return out


def _appendix_e() -> dict:
    """The parts of :func:`catalogue.fig_appendix_e` the plots use, without its Floquet runs."""
    from tslip.biped import BipedParams, BipedState, simulate
    from tslip.biped.metacentre import metacentric_test
    from tslip.biped.stored import load_gait

    pc, yc, tc, _ = load_gait("converged-e2")
    return {"e2": {"run": simulate(BipedParams(), BipedState.thesis(), 1)},
            "converged": {"metacentric": metacentric_test(pc, BipedState.from_array(yc), tc)}}


@pytest.fixture(scope="module")
def figures(data) -> dict:
    return {key: make() for key, make in report._plots(data).items()}


def _labelled(ax, which: str) -> bool:
    """``ax`` has a unit-carrying label on x or y, itself or through a shared axis."""
    get = f"get_{which}label"
    shared = getattr(ax, f"get_shared_{which}_axes")().get_siblings(ax)
    return any(UNIT.search(getattr(a, get)()) for a in [ax, *shared] if a.figure is ax.figure)


def test_every_report_figure_is_built(figures) -> None:
    shown = {f for figs, _ in report.SECTIONS for f in figs}
    assert set(figures) <= shown
    # every plotted figure of a section (4.6 is drawn with 4.5, 6.1 is a table)
    assert shown - set(figures) == {"4.6", "6.1"}


def test_every_axis_is_labelled_with_a_quantity_and_unit(figures) -> None:
    """No report axes is exempt: there are no image or table axes in the report."""
    bad = []
    for key, fig in figures.items():
        for k, ax in enumerate(fig.axes):
            for which in ("x", "y"):
                if not _labelled(ax, which):
                    bad.append(f"Figure {key} axes {k} {which}: "
                               f"{getattr(ax, f'get_{which}label')()!r}")
    assert not bad, "\n".join(bad)


def _texts(fig) -> list[str]:
    """Every label, title, tick-free text and legend entry of ``fig``."""
    out = [t.get_text() for t in fig.findobj(lambda a: hasattr(a, "get_text"))]
    return [t for t in out if t]


def test_units_are_typeset_one_way_no_caret_outside_mathtext(figures) -> None:
    """Issue 24: no "g^1/2" beside "g$^{1/2}$": every exponent is mathtext."""
    bad = [(key, t) for key, fig in figures.items() for t in _texts(fig)
           if "^" in re.sub(r"\$[^$]*\$", "", t)]
    assert not bad, bad


def test_panel_titles_are_words_not_study_identifiers(figures) -> None:
    names = set(catalogue.STUDIES)
    bad = [(key, ax.get_title()) for key, fig in figures.items() for ax in fig.axes
           if any(("_" in n and n in ax.get_title()) or ax.get_title().startswith(n + ":")
                  for n in names)]
    assert not bad, bad


@pytest.mark.parametrize("figs", [figs for figs, _, _ in report._STUDY_PAIRS])
def test_robustness_panels_share_the_multiplier_panels_x_range(figures, figs) -> None:
    eig, rob = figures[figs[0]], figures[figs[1]]
    (ax,) = eig.axes
    assert all(a.get_xlim() == pytest.approx(ax.get_xlim()) for a in rob.axes)


def _data_in_legend(fig) -> list[str]:
    """Legends drawn inside an axes that overlap one of its data points."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig).draw()
    bad = []
    for ax in fig.axes:
        leg = ax.get_legend()
        if leg is None:
            continue
        box = leg.get_window_extent()
        for line in ax.get_lines():
            xy = ax.transData.transform(np.asarray(line.get_xydata(), float))
            if line.get_linestyle() not in ("None", "none", "", " ") and len(xy) > 1:
                t = np.linspace(0.0, 1.0, 12)[:, None, None]  # points along each segment
                xy = (xy[:-1] + t * (xy[1:] - xy[:-1])).reshape(-1, 2)
            xy = xy[np.isfinite(xy).all(axis=1)]
            inside = ((xy[:, 0] > box.x0) & (xy[:, 0] < box.x1) & (xy[:, 1] > box.y0)
                      & (xy[:, 1] < box.y1))
            if inside.any():
                bad.append(f"{ax.get_title()!r}: {line.get_label()}")
    return bad


@pytest.mark.parametrize("key", ["4.4", "4.8", "4.12", "4.24", "E.3", "E.4"])
def test_legends_do_not_cover_data(figures, key) -> None:
    assert not _data_in_legend(figures[key])


@pytest.mark.parametrize("key", ["4.8", "4.12", "4.24", "E.3", "E.4"])
def test_crowded_legends_sit_outside_their_axes(figures, key) -> None:
    """Issue 24: these legends covered data; now beside or below the axes, whatever the data."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig = figures[key]
    FigureCanvasAgg(fig).draw()
    legends = [(ax, ax.get_legend()) for ax in fig.axes if ax.get_legend() is not None]
    assert legends
    for ax, leg in legends:
        assert not leg.get_window_extent().overlaps(ax.get_window_extent()), ax.get_title()


def test_figure_4_12_shows_the_trivial_multiplier(data, figures) -> None:
    """The trivial energy multiplier (1 at an undamped point) is drawn, apart from the rest."""
    (ax,) = figures["4.12"].axes
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    trivial = [ln for k, ln in lines.items() if "trivial" in k and "non-trivial" not in k]
    assert len(trivial) == 1
    f = data["leg_damping"].frame
    assert np.isfinite(trivial[0].get_ydata()).sum() == f["n_trivial"].sum()


def test_figure_4_4_marks_a_fall_at_its_step() -> None:
    """A run that falls (NaN dv) is drawn at its step as a fall, not dropped."""
    ok, fell = SimpleNamespace(dv=0.1, dv_expected=0.12), SimpleNamespace(dv=float("nan"),
                                                                          dv_expected=0.2)
    h = {"dh": (-0.2, -0.1, 0.05), "passive": [ok, ok, ok], "local_velocity": [fell, ok, ok]}
    fig = report._plots({"4.4": h})["4.4"]()
    right = fig.axes[1]
    (falls,) = [ln for ln in right.get_lines() if "fall" in ln.get_label()]
    assert list(falls.get_xdata()) == [-0.2]
    assert not [ln for ln in fig.axes[0].get_lines() if "fall" in ln.get_label()]


def _legend_texts(legend) -> list[str]:
    return [t.get_text() for t in legend.get_texts()]


def test_figure_4_11_legend_names_eqs_3_10_and_3_11(figures) -> None:
    fig = figures["4.11"]
    axes = np.array(fig.axes).reshape(2, -1)
    for ax in axes[0]:
        assert _legend_texts(ax.get_legend()) == ["$t_s$ model", "$t_s$ eq. 3.10"]
    for ax in axes[1]:
        assert _legend_texts(ax.get_legend()) == ["$t_f$ model", "$t_f$ eq. 3.11"]


def test_figure_4_10_legend_names_each_colour(data, figures) -> None:
    fig = figures["4.10"]
    (legend,) = fig.legends
    colour = {t.get_text(): to_rgba(h.get_facecolor())
              for t, h in zip(legend.get_texts(), legend.legend_handles, strict=True)}
    words = {0: "no periodic gait", 1: "periodic gait, unstable",
             2: "stable (non-trivial |λ| < 1)"}
    assert set(colour) == set(words.values())
    # the legend's colour of each class is the colour its grid cells are drawn in
    ax = fig.axes[0]
    (mesh,) = [c for c in ax.collections if isinstance(c, QuadMesh)]
    cells = mesh.to_rgba(np.asarray(mesh.get_array()).ravel())
    n = len(cells)
    assert n == data[f"grid_v{catalogue.GRID_SPEEDS[0]:g}"].spec.n_points
    for i in range(n):
        assert tuple(cells[i]) == pytest.approx(colour[words[_stable_code(i)]])


# -- the HTML page -----------------------------------------------------------


class _Page(HTMLParser):
    """Ids with their tag, class and text; every ``href``."""

    VOID = {"meta", "img", "br", "hr", "link", "input"}

    def __init__(self) -> None:
        super().__init__()
        self.ids: dict[str, dict] = {}
        self.hrefs: list[tuple[str, set[str]]] = []  # (href, ids of the enclosing elements)
        self.stack: list[dict] = []

    def handle_starttag(self, tag, attrs) -> None:  # noqa: ANN001
        a = dict(attrs)
        if "href" in a:
            self.hrefs.append((a["href"], {e["id"] for e in self.stack if e["id"]}))
        if tag in self.VOID:
            return
        el = {"tag": tag, "id": a.get("id"), "class": a.get("class", ""), "text": []}
        self.stack.append(el)
        if el["id"]:
            assert el["id"] not in self.ids, f"duplicate id {el['id']}"
            self.ids[el["id"]] = el

    def handle_endtag(self, tag) -> None:  # noqa: ANN001
        while self.stack:
            if self.stack.pop()["tag"] == tag:
                break

    def handle_data(self, d) -> None:  # noqa: ANN001
        for el in self.stack:
            el["text"].append(d)


def _claim(verdict: Verdict, k: int, **kw) -> ClaimResult:
    return ClaimResult(
        id=f"4.{k}-claim-{k}",
        figure=kw.pop("figure", "4.8"), text=f"claim number {k}", numbers={"x_max": 1.5 + k},
        verdict=verdict, quote=f"The thesis says <sentence {k}> & more.",
        source=f"Section 4.{k}", reading=f"we read it as reading {k}",
        evidence={"reading A": {"x_max": 1.0}, "variant tried": k} if verdict != Verdict.HOLDS
        else {}, note=f"note {k}", **kw)


@pytest.fixture
def page(tmp_path):
    claims = [_claim(Verdict.HOLDS, 0), _claim(Verdict.HOLDS, 1, figure="4.10"),
              _claim(Verdict.HOLDS_UNDER_READING, 2, figure="E.4"),
              _claim(Verdict.FAILS, 3, figure="4.11"), _claim(Verdict.FAILS, 4),
              _claim(Verdict.FAILS, 5, figure="C.1", error="ValueError: no gait")]
    path = report.write_report(tmp_path / "index.html", {}, claims, quick=True)
    p = _Page()
    text = path.read_text(encoding="utf-8")
    p.feed(text)
    return claims, p, text, json.loads((tmp_path / "claims.json").read_text())


def test_every_link_resolves_and_the_contents_reach_every_section_and_claim(page) -> None:
    claims, p, _, _ = page
    local = [h for h, _ in p.hrefs if h.startswith("#")]
    assert local and all(h[1:] in p.ids for h in local)
    toc = {h[1:] for h, within in p.hrefs if "contents" in within}
    sections = {"fig-" + figs[0].replace(".", "-") for figs, _ in report.SECTIONS}
    assert sections <= toc and sections <= set(p.ids)
    claim_ids = {k for k, el in p.ids.items() if "claim" in el["class"].split()}
    assert len(claim_ids) == len(claims) and claim_ids <= toc
    summary = {h[1:] for h, within in p.hrefs if "summary" in within}
    assert claim_ids | {"contents"} <= summary  # the summary links each claim and the contents


def test_each_claim_section_shows_quote_reading_numbers_verdict_evidence(page) -> None:
    claims, p, _, _ = page
    sections = [el for el in p.ids.values() if "claim" in el["class"].split()]
    kind = {report.VERDICT_CLASS[v]: v for v in Verdict}
    for c in claims:
        (el,) = [e for e in sections if c.text in "".join(e["text"])]
        body = "".join(el["text"])
        (cls,) = set(el["class"].split()) & set(kind)
        assert kind[cls] is c.verdict
        assert c.quote in body and c.source in body and c.reading in body
        assert f"{c.numbers['x_max']:.4g}" in body and c.verdict.value in body
        assert c.note in body and c.error in body
        if c.verdict is not Verdict.HOLDS:
            assert "variant tried" in body and "reading A" in body


def test_summary_counts_three_verdicts_and_escapes_quotes(page) -> None:
    claims, p, text, _ = page
    summary = "".join(p.ids["summary"]["text"])
    for v in Verdict:
        n = sum(c.verdict is v for c in claims)
        assert f"{v.value}: {n}" in summary
    for cls in ("holds", "reading", "fails"):
        assert f"class='verdict {cls}'" in text
    assert "<sentence" not in text and "&lt;sentence 3&gt; &amp; more" in text


def test_claims_json_schema_2_carries_id_verdict_quote_reading_evidence(page, tmp_path) -> None:
    claims, _, _, doc = page
    assert set(doc) == {"schema", "claims"} and doc["schema"] == 2
    js = doc["claims"]
    assert js == report.read_claims(tmp_path / "claims.json")
    assert len(js) == len(claims)
    for c, j in zip(claims, js, strict=True):
        assert set(j) == {"id", "figure", "claim", "verdict", "quote", "source", "reading",
                          "numbers", "evidence", "note", "error"}  # no "holds": the verdict
        assert j["verdict"] == c.verdict.value and j["id"] == c.id and j["claim"] == c.text
        for k in ("figure", "quote", "source", "reading", "note", "error"):
            assert j[k] == getattr(c, k)
        assert j["evidence"] == json.loads(json.dumps(c.evidence))


@pytest.mark.parametrize("old", [[{"figure": "4.1", "verdict": "holds", "holds": True}],
                                 {"claims": []}, {"schema": 3, "claims": []}])
def test_an_old_or_unknown_claims_json_is_refused_in_one_line(tmp_path, old) -> None:
    path = tmp_path / "claims.json"
    path.write_text(json.dumps(old))
    with pytest.raises(ValueError, match="schema") as exc:
        report.read_claims(path)
    assert "\n" not in str(exc.value) and "tslip reproduce" in str(exc.value)


def test_not_assessed_has_its_class_and_count_by_name(tmp_path) -> None:
    na = Verdict("not assessed")
    claims = [_claim(Verdict.HOLDS, 0), _claim(na, 1), _claim(na, 2, figure="4.19")]
    text = report.write_report(tmp_path / "index.html", {}, claims).read_text(encoding="utf-8")
    p = _Page()
    p.feed(text)
    assert "not assessed: 2" in "".join(p.ids["summary"]["text"])
    classes = [el["class"].split() for el in p.ids.values() if "claim" in el["class"].split()]
    assert sorted(c[1] for c in classes) == ["holds", "not-assessed", "not-assessed"]
    assert ".verdict.not-assessed{" in text and ".claim.not-assessed{" in text
    assert "class='verdict not-assessed'>not assessed</span>" in text


def test_numbers_show_typeset_units_and_rendered_quotes(tmp_path) -> None:
    """Units of number keys as superscripts, -0 as 0, a range's ends apart, no raw LaTeX."""
    c = ClaimResult(id="6.1-push", figure="6.1", text="push", verdict=Verdict.FAILS,
                    numbers={"push limit [g^1/2 L^1/2]": -0.725, "tilt [rad]": -0.0,
                             "stance time range [g^-1/2 L^1/2]": [0.19987, 0.20041],
                             "median [g^1/2 L^1/2]: passive": 2.1},
                    quote=r"push disturbance is $-0.73 \text{ g}^{1/2} \text{ L}^{1/2}$",
                    evidence={"by reading": {"slope [rad g^1/2 L^-1/2]": 1.0}})
    text = report.write_report(tmp_path / "index.html", {}, [c]).read_text(encoding="utf-8")
    (sec,) = re.findall(r"<div class='claim fails'.*?</div>", text, re.S)
    assert "push limit [g<sup>1/2</sup> L<sup>1/2</sup>]" in sec
    assert "<td>tilt [rad]</td><td>0</td>" in sec
    assert "[0.1999, 0.2004]" in sec  # 3 digits would print [0.2, 0.2]
    assert "slope [rad g<sup>1/2</sup> L<sup>-1/2</sup>]: 1" in sec
    assert "median [g<sup>1/2</sup> L<sup>1/2</sup>]: passive" in sec  # a unit inside a key
    assert "is -0.73 g<sup>1/2</sup> L<sup>1/2</sup>”" in sec
    assert "$" not in sec and "\\" not in sec and "^" not in sec


def test_reproduce_cli_prints_each_verdict_and_the_count_per_verdict(page, tmp_path,
                                                                     monkeypatch) -> None:
    """The CLI's table reads claims.json; the run itself is replaced by the page fixture's."""
    from typer.testing import CliRunner

    from tslip.cli import studies as studies_cli  # noqa: F401  (registers `tslip reproduce`)
    from tslip.cli.main import app

    claims = page[0]

    def run(out, progress, **kw):
        progress("workers", "2", 0.0)
        return tmp_path / "index.html"

    monkeypatch.setattr(report, "reproduce", run)
    r = CliRunner().invoke(app, ["reproduce", "--quick", "--out", str(tmp_path)],
                           env={"COLUMNS": "200"})
    assert r.exit_code == 0, r.output
    # (a cold numba cache adds the compile notice's lines: the suite's order decides)
    lines = [ln for ln in r.output.splitlines()
             if not ln.startswith(("first run: compiling", "  compiled "))]
    assert lines[0] == f"reproducing the thesis at quick resolution into {tmp_path}"
    n_figures = len(report.figure_inputs())
    assert lines[1].endswith(f"] {len(catalogue.STUDIES)} studies, {n_figures} figures on "
                             "2 workers")
    rows = [ln for ln in r.output.splitlines() if "claim number" in ln]
    assert len(rows) == len(claims)
    for c, row in zip(claims, rows, strict=True):
        assert row.rstrip().endswith(c.verdict.value)
    for v in Verdict:
        assert f"{v.value}: {sum(c.verdict is v for c in claims)}" in r.output


def test_figures_are_tasks_ready_when_their_data_arrive_and_drawn_alike_in_workers(data):
    """``tslip reproduce`` draws each figure on the worker pool once its data are in; the
    PNGs equal those drawn here, byte for byte."""
    from tslip.sweeps._schedule import run_tasks

    plots = report.ReportPlots()
    assert set(plots.inputs) == set(report._plots(data))  # every figure is a task
    assert plots.ready({}) == []
    grids = report.figure_inputs()["4.10"]
    assert len(grids) == 4
    partial = {k: data[k] for k in grids[:-1]}
    assert plots.ready(partial) == []  # Figure 4.10 waits for its last grid
    tasks = plots.ready({"E": data["E"], **partial})
    assert sorted(t.key[1] for t in tasks) == ["E.2", "E.3", "E.4"]
    tasks += plots.ready(data)
    assert sorted(t.key[1] for t in tasks) == sorted(plots.inputs)  # each once
    assert plots.ready(data) == [] and plots.cost == 0
    run_tasks(tasks, lambda task, result: plots.done(task, result) or [], workers=2)
    direct = {k: report.figure_png(make()) for k, make in report._plots(data).items()}
    assert plots.images == direct


def _laid_out_figure():
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.4, 3.6), layout="constrained")
    axs = fig.subplots(1, 2)
    m = axs[0].pcolormesh(np.arange(12.0).reshape(3, 4))
    fig.colorbar(m, ax=axs[0], label="a long colour-bar label [-]")
    axs[1].plot([0.0, 1.0], [1e4, 3e4], label="line")
    axs[1].set(xlabel="speed $v_0$ [$\\sqrt{gL}$]", ylabel="height [L]")
    axs[1].legend()
    fig.suptitle("a title")
    return fig


@pytest.mark.parametrize("dpi", [80, 120])
def test_figure_png_is_the_image_savefig_writes(dpi) -> None:
    """Laid out once at ``dpi`` (not in savefig's extra draw): the same PNG, the engine kept."""
    import base64
    import io

    buf = io.BytesIO()
    _laid_out_figure().savefig(buf, format="png", dpi=dpi)
    fig = _laid_out_figure()
    engine = fig.get_layout_engine()
    uri = report.figure_png(fig, dpi=dpi)
    assert base64.b64decode(uri.split(",", 1)[1]) == buf.getvalue()
    assert fig.get_layout_engine() is engine


def test_docs_verdict_table_is_read_from_claims_json(page, tmp_path) -> None:
    """The documentation's table (docs/_ext/tslip_docs.py) counts each verdict by name
    from the claims.json the report wrote, and lists every claim's id."""
    import importlib.util
    from pathlib import Path

    ext = Path(__file__).resolve().parents[2] / "docs" / "_ext" / "tslip_docs.py"
    spec = importlib.util.spec_from_file_location("tslip_docs", ext)
    assert spec is not None and spec.loader is not None
    docs = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(docs)
    claims = page[0]
    table = docs.verdict_table(report.read_claims(tmp_path / "claims.json"), "quick")
    first = table.splitlines()[0]
    counts = ", ".join(f"{sum(c.verdict is v for c in claims)} {v.value}" for v in Verdict)
    assert first == f"{len(claims)} claims at **quick** resolution: {counts}."
    rows = [ln for ln in table.splitlines() if ln.startswith("| `")]
    assert [r.split("`")[1] for r in rows] == [c.id for c in claims]
    assert all(c.verdict.value in r for c, r in zip(claims, rows, strict=True))


def test_figure_e3_fills_its_box() -> None:
    """The foot path is drawn at equal aspect: the figure is sized to it, no tall empty box."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from tslip.biped import BipedParams, BipedState, simulate
    from tslip.plotting.biped import plot_foot_path

    fig = plot_foot_path(simulate(BipedParams(), BipedState.thesis(), 1), stride=0)
    FigureCanvasAgg(fig).draw()
    (ax,) = fig.axes
    drawn = ax.get_window_extent()  # the axes box after equal aspect shrank it
    assert drawn.height / fig.bbox.height > 0.5  # 0.22 in the old 6 x 5 inch box


def _draw(plots, tasks) -> None:
    for task in tasks:
        plots.done(task, task.fn(*task.args, None))


def test_a_kept_figure_is_not_drawn_again_and_is_the_drawn_image(data, tmp_path) -> None:
    """A rerun takes each figure from ``figures/report-<key>.png`` when its key still holds:
    no draw, and the same image (the page is made of these images)."""
    subset = {"4.1": data["4.1"], "velocity": data["velocity"]}
    first = report.ReportPlots(tmp_path)
    tasks = first.ready(subset)
    assert sorted(t.key[1] for t in tasks) == ["4.1", "4.8", "4.9"] and first.drawn == 3
    _draw(first, tasks)
    for t in tasks:
        png = (tmp_path / "figures" / f"report-{t.key[1]}.png").read_bytes()
        assert report.png_key(png) == t.args[2] == report.figure_key(t.key[1], t.args[1])
    again = report.ReportPlots(tmp_path)
    assert again.cost == report.PLOT_SECONDS * (len(again.inputs) - 3)
    assert again.ready(subset) == [] and again.drawn == 0
    assert again.images == first.images
    plain = report.ReportPlots()  # no folder: every figure drawn, as before
    _draw(plain, plain.ready(subset))
    assert plain.drawn == 3 and set(plain.images) == set(first.images)


def test_a_changed_input_or_plotting_code_draws_again(data, tmp_path, monkeypatch) -> None:
    import shutil
    from pathlib import Path

    import tslip
    from tslip import _codehash as ch

    study = data["velocity"]
    subset = {"4.1": data["4.1"], "velocity": study}
    first = report.ReportPlots(tmp_path)
    _draw(first, first.ready(subset))

    def drawn(inputs) -> list[str]:
        plots = report.ReportPlots(tmp_path)
        return sorted(t.key[1] for t in plots.ready(inputs))

    timed = StudyResult(study.spec, study.frame.assign(seconds=3.0), {"seconds": 9.0})
    assert drawn({**subset, "velocity": timed}) == []  # timings are not drawn
    frame = study.frame.copy()
    frame.loc[1, "max_nontrivial"] += 1e-9
    assert drawn({**subset, "velocity": StudyResult(study.spec, frame, study.meta)}) == [
        "4.8", "4.9"]
    (tmp_path / "figures" / "report-4.1.png").write_bytes(b"\x89PNG\r\n\x1a\n damaged")
    assert drawn(subset) == ["4.1"]
    _draw(first, first.ready({}))  # nothing new
    root = tmp_path / "src" / "tslip"  # an edit of the plotting code
    shutil.copytree(Path(tslip.__file__).parent, root,
                    ignore=shutil.ignore_patterns("__pycache__"))
    f = root / "plotting" / "studies.py"
    f.write_text(f.read_text() + "\n_EDIT = 1\n")
    monkeypatch.setattr(ch, "_ROOT", root)
    ch.cache_clear()
    report._plotting_code.cache_clear()
    try:
        assert drawn(subset) == ["4.1", "4.8", "4.9"]
    finally:
        monkeypatch.undo()
        ch.cache_clear()
        report._plotting_code.cache_clear()


def test_png_key_reads_the_text_chunk_only_of_a_png() -> None:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(2, 1))
    fig.subplots().plot([0, 1])
    import base64

    png = base64.b64decode(report.figure_png(fig, key="abc123").split(",", 1)[1])
    assert report.png_key(png) == "abc123"
    assert report.png_key(base64.b64decode(report.figure_png(fig).split(",", 1)[1])) is None
    assert report.png_key(b"GIF89a") is None and report.png_key(png[:20]) is None


def test_a_recorded_run_keeps_its_figure_key_between_computations() -> None:
    """Figure 4.5's data computed twice (a rerun) give one key: a recorded run's step and
    event lists are keyed by their items, not by their arrays' unused rows."""
    first, second = catalogue.fig_step_down(n_steps=3), catalogue.fig_step_down(n_steps=3)
    assert report.figure_key("4.5", {"4.5": first}) == report.figure_key("4.5", {"4.5": second})
    changed = catalogue.fig_step_down(n_steps=4)
    assert report.figure_key("4.5", {"4.5": changed}) != report.figure_key("4.5", {"4.5": first})
