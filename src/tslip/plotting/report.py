"""The ``tslip reproduce`` report: one self-contained HTML page.

Every image is a base64 PNG inside the page, and the page has no external
references (no scripts, fonts or style sheets), so it opens from disk with
no server and no internet. One section per thesis figure: our plot, the
thesis's claim, the numbers we measured and whether the claim holds; then
the Table 6.2-style stride table and the Section 6.1 robustness numbers.

Each figure's PNG is kept in ``out_dir/figures/report-<figure>.png`` with the
key it was drawn under in a text chunk of the PNG (:func:`figure_key`: its
input data and the plotting code's hash): a rerun whose figure has the same
key takes the file instead of drawing it again.

Over 600 lines: one concept, the report: its keyed figures, its page and claims.json.
"""

from __future__ import annotations

import base64
import dataclasses
import functools
import hashlib
import html
import io
import json
import pickle
from collections.abc import Callable, Mapping, Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .. import __version__
from .._codehash import code_hash
from .._io import atomic_write, write_json
from .._results import encode
from ..model.units import UNIT
from ..sweeps.claims import Verdict, count_verdicts
from .notation import axis_label, key_html, tex_html, unit_html, value

if TYPE_CHECKING:  # matplotlib is imported where a figure is drawn: a warm rerun draws none
    from matplotlib.figure import Figure

__all__ = ["CLAIMS_SCHEMA", "PLOT_SECONDS", "SECTIONS", "ReportPlots", "claims_json", "compute",
           "figure_inputs", "figure_key", "figure_png", "plot_task", "png_key", "read_claims",
           "render_ready", "reproduce", "write_report"]


#: The resolution of the report's figures.
DPI = 80
#: The PNG text chunk's keyword that holds a cached figure's key (:func:`figure_key`).
KEY_CHUNK = "tslip-figure-key"
_URI = "data:image/png;base64,"


def figure_png(fig: Figure, dpi: int = DPI, key: str | None = None) -> str:
    """A figure as a ``data:image/png;base64,...`` URI; ``key`` in its text chunk ``KEY_CHUNK``.

    A figure with a layout engine is laid out here, at ``dpi``, and saved with
    the engine switched off (then restored): ``savefig`` would lay it out in a
    first, unrendered drawing of every artist and then draw it again, a sixth of
    a report figure's time. The image is the same to the byte.
    """
    engine = fig.get_layout_engine()
    buf = io.BytesIO()
    meta = {KEY_CHUNK: key} if key is not None else None
    if engine is None:
        fig.savefig(buf, format="png", dpi=dpi, metadata=meta)
    else:
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        fig.dpi = dpi
        FigureCanvasAgg(fig)
        engine.execute(fig)
        fig.set_layout_engine(None)
        try:
            fig.savefig(buf, format="png", dpi=dpi, metadata=meta)
        finally:
            fig.set_layout_engine(engine)
    return _URI + base64.b64encode(buf.getvalue()).decode("ascii")


def png_key(png: bytes) -> str | None:
    """The ``KEY_CHUNK`` text of a PNG file's bytes, or None (not a PNG, no such chunk).

    Reads the chunk layout only (length, type, data, CRC; the PNG specification):
    a damaged or foreign file has no key.
    """
    if not png.startswith(b"\x89PNG\r\n\x1a\n"):
        return None
    pos = 8
    while pos + 8 <= len(png):
        n = int.from_bytes(png[pos:pos + 4], "big")
        kind, body = png[pos + 4:pos + 8], png[pos + 8:pos + 8 + n]
        if kind == b"tEXt":
            word, _, text = body.partition(b"\0")
            if word == KEY_CHUNK.encode():
                return text.decode("latin-1")
        if kind in (b"IDAT", b"IEND"):  # text chunks come before the image data
            return None
        pos += 12 + n
    return None


@functools.cache
def _plotting_code() -> str:
    """The hash of the report's plotting code (:data:`ReportPlots.modules`, their imports
    from tslip) and of the versions of the libraries that draw."""
    from importlib import metadata

    libs = ",".join(f"{lib}={metadata.version(lib)}" for lib in ("matplotlib", "pillow"))
    return f"{code_hash(*ReportPlots.modules)}|{libs}"


def _items(kind: str, items: tuple[Any, ...]) -> None:
    """What :class:`_Canonical` pickles a sequence type as (never called: nothing unpickles)."""


class _Canonical(pickle.Pickler):
    """A pickler that writes a sequence class other than list and tuple (e.g. a recorded
    run's :class:`~tslip.simulation.result.StepList`, built on first read from arrays
    whose unused rows are not initialised) as its type's name and its items."""

    def reducer_override(self, obj: Any) -> Any:
        if (isinstance(obj, Sequence) and not isinstance(obj, (list, tuple, str, bytes, range))
                and not dataclasses.is_dataclass(obj)):
            return _items, (type(obj).__qualname__, tuple(obj))
        return NotImplemented


def _data_digest(v: Any) -> str:
    """SHA-256 of one figure input.

    A study result by its spec and columns only (pickled, :class:`_Canonical`):
    its run record and its ``seconds`` column are timings, which no figure
    draws. Anything else by its saved form (:func:`tslip._results.encode`, as
    JSON with sorted keys), which depends on the values only: a figure's data
    computed and the same data read back from the report folder
    (:func:`tslip.sweeps.reproduce.figure_load`) give one key, where their
    pickles differ (objects shared or not, arrays in either memory order, a
    run's table derived or not). Data that cannot be saved so is pickled. Two
    digests of the same data that differ draw the figure again, never keep a
    stale one.
    """
    if hasattr(v, "frame") and hasattr(v, "spec") and hasattr(v, "meta"):
        f = v.frame.drop(columns=["seconds"], errors="ignore")
        v = ("study", v.spec, list(f.columns), [str(t) for t in f.dtypes], list(f.index),
             f.to_numpy(dtype=object))
    else:
        try:
            text = json.dumps(encode(v), sort_keys=True, allow_nan=False)
        except (TypeError, ValueError):
            pass
        else:
            return hashlib.sha256(text.encode()).hexdigest()
    buf = io.BytesIO()
    _Canonical(buf, protocol=5).dump(v)
    return hashlib.sha256(buf.getvalue()).hexdigest()


def figure_key(fkey: str, inputs: Mapping[str, Any],
               digests: dict[tuple[str, int], str] | None = None) -> str:
    """The key a figure is drawn under: SHA-256 of its inputs and of the plotting code.

    Each input by :func:`_data_digest` (``digests`` keeps them by key and object,
    for inputs several figures share), the figure, :data:`DPI` and
    :func:`_plotting_code`: a change to any of them draws the figure again.
    Taken when the data arrive, before a figure is drawn from them (drawing may
    fill an object's caches built on first read, which pickle).
    """
    digests = {} if digests is None else digests
    h = hashlib.sha256(f"{fkey}|{DPI}|{_plotting_code()}".encode())
    for k in sorted(inputs):
        d = digests.get((k, id(inputs[k])))
        if d is None:
            d = digests[(k, id(inputs[k]))] = _data_digest(inputs[k])
        h.update(f"|{k}={d}".encode())
    return h.hexdigest()


#: Controller studies of Figures 4.24-4.25: legend label -> study name.
_CONTROLLERS = {"passive": "mass_offset", "global PD": "controller_global_pd",
                "local velocity": "controller_local_velocity",
                "constant torque": "controller_constant_torque"}
#: The studies drawn as a multipliers figure and a robustness figure: (figures, study,
#: what varies in the thesis's caption words).
_STUDY_PAIRS = ((("4.8", "4.9"), "velocity", "velocity"),
                (("4.12", "4.13"), "leg_damping", "leg damping"),
                (("4.14", "4.15"), "hip_damping", "hip damping"),
                (("4.16", "4.17"), "mass_offset", "mass offset"),
                (("4.18", "4.19"), "stiffness", "leg stiffness"),
                (("4.20", "4.21"), "touchdown_angle", "initial leg angle"),
                (("4.22", "4.23"), "retraction", "normalized swing-leg retraction rate"))
_STRIDE_STUDIES = ("stride_v0", "stride_k", "stride_beta0")


def figure_inputs() -> dict[str, tuple[str, ...]]:
    """The data keys each report figure is drawn from (:func:`_plots`), by figure."""
    from ..sweeps.catalogue import GRID_SPEEDS

    inputs: dict[str, tuple[str, ...]] = {
        k: (k,) for k in ("4.1", "4.2", "4.3", "6.2", "4.4", "4.5", "4.7", "C.1")}
    inputs.update(dict.fromkeys(("E.2", "E.3", "E.4"), ("E",)))
    inputs["4.10"] = tuple(f"grid_v{v:g}" for v in GRID_SPEEDS)
    inputs["4.11"] = _STRIDE_STUDIES
    inputs["4.24"] = inputs["4.25"] = tuple(_CONTROLLERS.values())
    for figs, name, _ in _STUDY_PAIRS:
        inputs.update(dict.fromkeys(figs, (name,)))
    return inputs


def _plots(data: Mapping[str, Any]) -> dict[str, Callable[[], Figure]]:
    """Each report figure's plot, from ``data`` (its keys: :func:`figure_inputs`)."""
    from ..sweeps.catalogue import GRID_SPEEDS
    from . import biped as b
    from . import gait as g
    from . import studies as s

    def pair(name: str, words: str) -> dict[str, Callable[[], Figure]]:
        return {"eig": lambda: s.plot_study_multipliers(
                    data[name], title=f"Eigenvalue magnitudes over varying {words}"),
                "rob": lambda: s.plot_study_robustness(
                    data[name], title=f"Robustness over varying {words}")}

    def fig44() -> Figure:
        from matplotlib.figure import Figure

        h = data["4.4"]
        fig = Figure(figsize=(8.0, 3.2), layout="constrained")
        axes = fig.subplots(1, 2, sharey=True)
        dh = np.asarray(h["dh"], float)
        for a, key, title in ((axes[0], "passive", "passive vs eq. 3.8"),
                              (axes[1], "local_velocity", "local velocity control")):
            dv = np.array([r.dv for r in h[key]], float)
            fell = ~np.isfinite(dv)  # a run that falls has no converged speed
            a.plot(dh[~fell], dv[~fell], "o", label="model")
            if key == "passive":
                a.plot(dh, [r.dv_expected for r in h[key]], "-", label="eq. 3.8")
            if fell.any():
                a.plot(dh[fell], np.zeros(int(fell.sum())), "X", color="C3", ms=9,
                       label="falls (no Δv)")
            a.axhline(0, color="k", lw=0.6)
            a.set_xlabel(axis_label(r"ground step $\Delta h$", UNIT["length"]))
            a.set_title(title, fontsize=9)
            a.legend(fontsize=7)
        axes[0].set_ylabel(axis_label(r"$\Delta v$", UNIT["speed"]))
        return fig

    ctrl = _CONTROLLERS
    plots: dict[str, Callable[[], Figure]] = {
        "4.1": lambda: g.plot_impulse_linearisation(data["4.1"]),
        "4.2": lambda: g.plot_pitch_impulse(data["4.2"]),
        "4.3": lambda: g.plot_pitch_impulse(data["4.3"]),
        "6.2": lambda: g.plot_pitch_impulse(data["6.2"]),
        "4.4": fig44,
        "4.5": lambda: g.plot_step_down_response(data["4.5"]),
        "4.7": lambda: g.plot_velocity_angle_effect(data["4.7"]),
        "C.1": lambda: g.plot_friction([data["C.1"]["table2.1"], data["C.1"]["table6.1"]],
                                       titles=["Table 2.1", "Table 6.1"]),
        "E.2": lambda: b.plot_tracking(data["E"]["e2"]["run"]),
        "E.3": lambda: b.plot_foot_path(data["E"]["e2"]["run"], stride=0),
        "E.4": lambda: b.plot_metacentric(data["E"]["converged"]["metacentric"]),
        "4.10": lambda: s.plot_stable_grid({v: data[f"grid_v{v:g}"] for v in GRID_SPEEDS}),
        "4.11": lambda: s.plot_stride_times({n: data[n] for n in _STRIDE_STUDIES}),
        "4.24": lambda: s.plot_controllers_multipliers({k: data[v] for k, v in ctrl.items()}),
        "4.25": lambda: s.plot_controllers_robustness({k: data[v] for k, v in ctrl.items()}),
    }
    for figs, name, words in _STUDY_PAIRS:
        p = pair(name, words)
        plots[figs[0]], plots[figs[1]] = p["eig"], p["rob"]
    return plots


#: Report sections: (figure keys shown together, title).
SECTIONS: tuple[tuple[tuple[str, ...], str], ...] = (
    (("4.1",), "Figure 4.1: impulse linearisation in pitch (passive)"),
    (("4.2",), "Figure 4.2: impulse under a pitch disturbance (passive)"),
    (("4.3",), "Figure 4.3: impulse under a pitch disturbance (global PD)"),
    (("4.4",), "Figure 4.4: speed change after a ground step"),
    (("4.5", "4.6"), "Figures 4.5, 4.6: response to a 0.2 L step down"),
    (("4.7",), "Figure 4.7: touch-down velocity angle"),
    (("4.8", "4.9"), "Figures 4.8, 4.9: speed v0"),
    (("4.10",), "Figure 4.10: stable k x beta0 region (local velocity control)"),
    (("4.11",), "Figure 4.11: stance and flight time vs eqs. 3.10-3.11"),
    (("4.12", "4.13"), "Figures 4.12, 4.13: leg damping (constant torque)"),
    (("4.14", "4.15"), "Figures 4.14, 4.15: hip damping (constant torque)"),
    (("4.16", "4.17"), "Figures 4.16, 4.17: mass offset r"),
    (("4.18", "4.19"), "Figures 4.18, 4.19: leg stiffness k"),
    (("4.20", "4.21"), "Figures 4.20, 4.21: touch-down angle beta0"),
    (("4.22", "4.23"), "Figures 4.22, 4.23: swing-leg retraction"),
    (("4.24", "4.25"), "Figures 4.24, 4.25: four controllers over r"),
    (("6.1", "6.2"), "Section 6.1, Tables 6.1-6.2, Figure 6.2: the elliptical-runner fit"),
    (("C.1",), "Figure C.1: friction ratio"),
    (("E.2", "E.3", "E.4"), "Appendix E, Figures E.2-E.4: the two-legged model (tracking and "
     "stability from Table E.2; metacentric test on the converged periodic gait)"),
)

_CSS = """
body{font-family:sans-serif;max-width:1000px;margin:1em auto;padding:0 1em;color:#222}
h2{border-bottom:1px solid #ccc;padding-top:.6em}
table{border-collapse:collapse;margin:.5em 0;font-size:.9em}
td,th{border:1px solid #ccc;padding:3px 7px;text-align:left;vertical-align:top}
.verdict{font-weight:bold;white-space:nowrap}.verdict.holds{color:#146c14}
.verdict.reading{color:#a05a00}.verdict.fails{color:#b00}.failed{color:#b00}
.verdict.not-assessed{color:#3a5a8c}
.claim{border-left:4px solid #ccc;padding:.2em .8em;margin:1em 0}
.claim.holds{border-color:#146c14}.claim.reading{border-color:#d08a1c}
.claim.fails{border-color:#b00}.claim.not-assessed{border-color:#7f9cc8;border-left-style:dashed}
.claim h3{font-size:1em;margin:.3em 0}
.up{float:right;font-size:.8em;font-weight:normal}
blockquote{margin:.3em 0 .3em 1em;font-style:italic}cite{font-style:normal;color:#555}
img{max-width:100%;display:block;margin:.4em 0}.note{color:#555;font-size:.9em}
nav ol{columns:2;font-size:.9em}nav ol ol{columns:1;font-size:.95em}
code{font-size:.85em}
"""

#: CSS class of each verdict, by its text (a :class:`Verdict` is its text): "not assessed"
#: (too few points for the check's statistic; never a failure) is blue and dashed.
VERDICT_CLASS: dict[str, str] = {"holds": "holds", "holds under a stated reading": "reading",
                                 "does not hold": "fails", "not assessed": "not-assessed"}


def _e(x: Any) -> str:
    return html.escape(str(x))


def _value_html(v: Any, key: str) -> str:
    """A claim's number as HTML (:func:`.notation.value`), units of nested keys typeset."""
    if isinstance(v, Mapping):
        return "; ".join(f"{key_html(str(k))}: {_value_html(x, str(k))}" for k, x in v.items())
    return _e(value(v, key))


def _verdict(c: Any) -> Verdict:
    return Verdict(c.verdict)


_UP = "<a class='up' href='#contents'>contents</a>"


def _claim_ids(claims: Sequence[Any]) -> list[str]:
    """The HTML id of each claim's section: ``claim-1``, ``claim-2``, ..."""
    return [f"claim-{i + 1}" for i in range(len(claims))]


def _verdict_span(c: Any) -> str:
    v = _verdict(c)
    return f"<span class='verdict {VERDICT_CLASS[v]}'>{_e(v.value)}</span>"


def _summary_table(claims: Sequence[Any], ids: Sequence[str]) -> str:
    rows = [f"<tr><td>{_e(c.figure)}</td><td><a href='#{i}'>{tex_html(c.text)}</a></td>"
            f"<td>{_verdict_span(c)}</td></tr>" for c, i in zip(claims, ids, strict=True)]
    return ("<table><tr><th>figure</th><th>thesis claim</th><th>verdict</th></tr>"
            + "".join(rows) + "</table>")


def _numbers_table(numbers: Mapping[str, Any]) -> str:
    return ("<table>" + "".join(f"<tr><td>{key_html(k)}</td><td>{_value_html(v, k)}</td></tr>"
                                for k, v in numbers.items()) + "</table>")


def _claim_section(c: Any, cid: str) -> str:
    """One claim: thesis sentence and source, our reading, numbers, verdict, evidence, note."""
    v = _verdict(c)
    out = [f"<div class='claim {VERDICT_CLASS[v]}' id='{cid}'>",
           f"<h3>Figure {_e(c.figure)}: {tex_html(c.text)}{_UP}</h3>"]
    if c.quote:
        src = f" <cite>({_e(c.source)})</cite>" if c.source else ""
        out.append(f"<blockquote class='quote'>“{tex_html(c.quote)}”{src}</blockquote>")
    else:
        out.append("<p class='quote note'>Thesis sentence not recorded.</p>")
    if c.reading:
        out.append(f"<p class='reading-text'><b>Our reading:</b> {tex_html(c.reading)}</p>")
    out.append("<p><b>Our numbers:</b></p>" + (_numbers_table(c.numbers) if c.numbers
                                                else "<p class='note'>none</p>"))
    if c.error:
        out.append(f"<p class='note'><i>{_e(c.error)}</i></p>")
    out.append(f"<p><b>Verdict:</b> {_verdict_span(c)}</p>")
    if c.evidence:
        out.append("<div class='evidence'><p><b>Evidence:</b></p>"
                   + _numbers_table(c.evidence) + "</div>")
    elif v is not Verdict.HOLDS:
        out.append("<p class='evidence note'>No further evidence recorded.</p>")
    if c.note:
        out.append(f"<p class='note'>{tex_html(c.note)}</p>")
    out.append("</div>")
    return "\n".join(out)


def _counts_html(claims: Sequence[Any]) -> str:
    parts = [f"<span class='verdict {VERDICT_CLASS[v]}'>{_e(v.value)}: {n}</span>"
             for v, n in count_verdicts(claims).items()]
    return (f"<p class='counts'>{len(claims)} claims; " + ", ".join(parts)
            + ". Every figure and claim is listed in the <a href='#contents'>contents</a>.</p>")


def _sec_id(figs: Sequence[str]) -> str:
    return "fig-" + figs[0].replace(".", "-")


def _toc(claims: Sequence[Any], ids: Sequence[str]) -> str:
    """Contents: every figure section and, under it, its claims."""
    items = ["<li><a href='#summary'>Summary</a></li>"]
    for figs, title in SECTIONS:
        sub = "".join(f"<li><a href='#{i}'>{tex_html(c.text)}</a> {_verdict_span(c)}</li>"
                      for c, i in zip(claims, ids, strict=True) if c.figure in figs)
        items.append(f"<li><a href='#{_sec_id(figs)}'>{_e(title)}</a>"
                     + (f"<ol>{sub}</ol>" if sub else "") + "</li>")
    if _orphans(claims):
        items.append("<li><a href='#other-claims'>Other claims</a></li>")
    items.append("<li><a href='#studies'>Studies</a></li>")
    return "<nav id='contents'><h2>Contents</h2><ol>" + "".join(items) + "</ol></nav>"


def _orphans(claims: Sequence[Any]) -> list[int]:
    """Indices of claims whose figure has no section."""
    shown = {f for figs, _ in SECTIONS for f in figs}
    return [k for k, c in enumerate(claims) if c.figure not in shown]


def _table6(data: Mapping[str, Any]) -> str:
    t = data.get("table6.1")
    if t is None:
        return ""
    time, freq = UNIT["time"], UNIT["frequency"]
    rows6 = [(f"Stance duration t<sub>s</sub> [{unit_html(time)}]", 0.58, "0.58 ± 0.03",
              "stance_time"),
             (f"Flight duration t<sub>f</sub> [{unit_html(time)}]", 0.13, "0.13 ± 0.02",
              "flight_time"),
             ("Duty factor d [-]", 0.82, "0.81 ± 0.02", "duty_factor"),
             (f"Step frequency f [{unit_html(freq)}]", 1.41, "1.40 ± 0.07", "step_frequency")]
    s = ("<h3>Table 6.2: stride of the Table 6.1 model</h3><table><tr><th>quantity</th>"
         "<th>Ell. Runner</th><th>thesis TSLIP</th><th>ours</th></tr>")
    s += "".join(f"<tr><td>{a}</td><td>{c}</td><td>{b}</td><td>{t[k]:.3f}</td></tr>"
                 for a, b, c, k in rows6) + "</table>"
    rob = [("Largest multiplier |λ| [-]", 0.92, "max_nontrivial"),
           (f"Step-down Δh [{UNIT['length']}]", -0.12, "step_down"),
           (f"Push Δẋ [{unit_html(UNIT['speed'])}]", -0.73, "push"),
           (f"Pitch rate Δφ̇ [{unit_html(UNIT['angular_velocity'])}]", -1.50, "pitch_rate"),
           (f"Controller reference α̇<sub>ref</sub> (solved) "
            f"[{unit_html(UNIT['angular_velocity'])}]", 2.42, "alphad_ref")]
    s += ("<h3>Section 6.1: stability and robustness of the Table 6.1 model</h3><table>"
          "<tr><th>quantity</th><th>thesis</th><th>ours</th></tr>")
    s += "".join(f"<tr><td>{a}</td><td>{b:.2f}</td><td>{t[k]:.3f}</td></tr>"
                 for a, b, k in rob) + "</table>"
    s += ("<p class='note'>docs/conventions.md lists the pitch-rate limit -1.50 and the controller "
          "reference 2.42 as known not to reproduce with the model's equations.</p>")
    return s


def _global_pd_note(data: Mapping[str, Any]) -> str:
    res = data.get("controller_global_pd")
    if res is None:
        return ""
    f = res.frame
    conv = f[f["converged"].astype(bool)]
    worst = f"{conv['residual'].max():.1e}" if len(conv) else "–"
    return ("<p class='note'>The global PD controller has one equation more than unknowns, so "
            "its gaits are not exactly periodic (thesis: accepted <code>C1 &lt; 1e-4</code>, "
            "eq. 2.22). We accept a max-norm touch-down residual up to 1e-2 for this "
            f"controller only; the largest residual reached is {worst} ({len(conv)} of "
            f"{len(f)} points). Its multipliers and robustness are those of this "
            "near-periodic gait.</p>")


#: Estimated CPU seconds to draw one report figure (:class:`ReportPlots`).
PLOT_SECONDS = 0.5


def plot_task(fkey: str, inputs: Mapping[str, Any], key: str | None = None,
              tick: Any = None) -> str | None:
    """Figure ``fkey`` as a PNG data URI, from its inputs (a task, in a worker), ``key`` in it.

    None if the plot fails: :func:`write_report` draws it again here and
    reports the error in the page.
    """
    try:
        return figure_png(_plots(inputs)[fkey](), key=key)
    except Exception:  # noqa: BLE001 - reported by write_report
        return None


class ReportPlots:
    """The report's figures as tasks of ``tslip reproduce``'s scheduler.

    Passed to :func:`tslip.sweeps.reproduce.run_all` as ``extra``: each
    figure is a task (:func:`plot_task`) made ready as soon as the data it is
    drawn from (:func:`figure_inputs`) have arrived, so the figures are drawn
    on the worker pool while the rest is computed; ``images`` collects them.

    With ``out_dir``, each drawn figure is kept in ``out_dir/figures/report-<figure>.png``
    under its :func:`figure_key`, and a figure whose file holds the same key is
    taken from it (no task): a rerun draws only what changed. Written atomically,
    read as PNG bytes (the key from its text chunk, :func:`png_key`).
    """

    #: What :func:`plot_task` imports (for the workers to import once).
    modules = (__name__, "tslip.plotting.biped", "tslip.plotting.gait", "tslip.plotting.studies")

    def __init__(self, out_dir: str | Path | None = None) -> None:
        self.inputs = figure_inputs()
        self.images: dict[str, str] = {}
        self.sent: set[str] = set()
        self.folder = None if out_dir is None else Path(out_dir) / "figures"
        self.drawn = 0  # figures sent to be drawn (the rest came from their files)
        self.digests: dict[tuple[str, int], str] = {}  # (input, id) -> its data's digest

    def path(self, fkey: str) -> Path | None:
        """Where figure ``fkey`` is kept (None without ``out_dir``)."""
        return None if self.folder is None else self.folder / f"report-{fkey}.png"

    @property
    def cost(self) -> float:
        """Estimated seconds of the figures not yet sent (a figure with a file: none)."""
        kept = {f for f in self.inputs if (p := self.path(f)) is not None and p.is_file()}
        return PLOT_SECONDS * len(set(self.inputs) - self.sent - kept)

    def _kept(self, fkey: str, key: str) -> str | None:
        """Figure ``fkey``'s file as a data URI if it holds ``key``."""
        path = self.path(fkey)
        try:
            png = path.read_bytes() if path is not None else b""
        except OSError:
            return None
        return _URI + base64.b64encode(png).decode("ascii") if png_key(png) == key else None

    def ready(self, data: Mapping[str, Any]) -> list[Any]:
        """Tasks for the figures whose data ``data`` now holds (each figure once)."""
        from ..sweeps._schedule import Task

        out = []
        for fkey, keys in self.inputs.items():
            if fkey not in self.sent and all(k in data for k in keys):
                self.sent.add(fkey)
                inputs = {k: data[k] for k in keys}
                key = (figure_key(fkey, inputs, self.digests) if self.folder is not None
                       else None)
                if key is not None and (kept := self._kept(fkey, key)) is not None:
                    self.images[fkey] = kept
                    continue
                self.drawn += 1
                out.append(Task(("plot", fkey), plot_task, (fkey, inputs, key), PLOT_SECONDS))
        return out

    def done(self, task: Any, result: str | None) -> None:
        if result is None:
            return
        fkey = task.key[1]
        self.images[fkey] = result
        path = self.path(fkey)
        if path is not None:
            png = base64.b64decode(result.removeprefix(_URI))
            atomic_write(path, lambda tmp: Path(tmp).write_bytes(png))


def render_ready(data: Mapping[str, Any], images: dict[str, str]) -> None:
    """Add to ``images`` every figure whose data ``data`` holds (for plotting as data arrive)."""
    for fkey, make in _plots(data).items():
        if fkey not in images:
            try:
                images[fkey] = figure_png(make())
            except Exception:  # noqa: BLE001 - data not there yet; write_report reports errors
                pass


def write_report(path: str | Path, data: Mapping[str, Any], claims: Sequence[Any], *,
                 quick: bool = False, seconds: float | None = None,
                 workers: int | None = None, images: Mapping[str, str] | None = None) -> Path:
    """Write the report page and ``claims.json`` beside it; return the page's path.

    The page: a summary with the count of claims per verdict (holds; holds
    under a stated reading; does not hold) and a table linking each claim
    to its section, a table of contents, one section per figure (our plots,
    then each claim with the thesis sentence and its source, our reading,
    our numbers, the verdict, its evidence and a note), and the studies.
    ``images``: figures already rendered (:func:`render_ready`), by key.
    """
    images = images or {}
    drawn = figure_inputs()  # the report's figures (the keys of _plots)
    # the plots import matplotlib (0.6 s): only for a figure not among the images
    plots = _plots(data) if set(drawn) - set(images) else {}
    ids = _claim_ids(claims)
    parts = [f"<!DOCTYPE html><html><head><meta charset='utf-8'>"
             f"<title>tslip reproduce</title><style>{_CSS}</style></head><body>",
             "<h1>TSLIP thesis reproduction</h1>",
             f"<p>tslip {_e(__version__)}, {'quick' if quick else 'full'} resolution, "
             f"{datetime.now(UTC):%Y-%m-%d %H:%M} UTC"
             + (f", {seconds:.1f} s on {workers} worker(s)" if seconds is not None else "")
             + ". A claim that does not hold is shown with our numbers and the evidence; no "
             "study was tuned to agree. A claim that holds under a stated reading shows the "
             "reading and the numbers of each reading.</p>",
             "<section id='summary'><h2>Summary</h2>", _counts_html(claims),
             _summary_table(claims, ids), "</section>", _toc(claims, ids)]
    for figs, title in SECTIONS:
        parts.append(f"<section id='{_sec_id(figs)}'><h2>{_e(title)}{_UP}</h2>")
        for fkey in figs:
            if fkey in drawn:
                try:
                    src = images.get(fkey) or figure_png(plots[fkey]())
                    parts.append(f"<img alt='Figure {fkey}' src='{src}'>")
                except KeyError:
                    parts.append(f"<p class='note'>Figure {fkey}: data not computed.</p>")
                except Exception as exc:  # noqa: BLE001 - a broken plot must not lose the rest
                    parts.append(f"<p class='failed'>Figure {fkey}: plot failed: {_e(exc)}</p>")
        if "4.24" in figs:
            parts.append(_global_pd_note(data))
        if "6.1" in figs:
            parts.append(_table6(data))
        parts += [_claim_section(c, i) for c, i in zip(claims, ids, strict=True)
                  if c.figure in figs]
        parts.append("</section>")
    if _orphans(claims):
        parts.append("<section id='other-claims'><h2>Other claims</h2>")
        parts += [_claim_section(claims[k], ids[k]) for k in _orphans(claims)]
        parts.append("</section>")
    studies = {k: v.meta for k, v in data.items() if hasattr(v, "meta") and hasattr(v, "frame")}
    parts.append("<section id='studies'><h2>Studies</h2><table><tr><th>study</th>"
                 "<th>description</th><th>points</th><th>computed</th><th>seconds</th></tr>")
    for k, m in studies.items():
        desc = data[k].spec.description
        parts.append(f"<tr><td>{_e(k)}</td><td>{_e(desc)}</td><td>{m.get('points')}</td>"
                     f"<td>{m.get('computed')}</td><td>{m.get('seconds', 0):.1f}</td></tr>")
    parts.append("</table><p class='note'>Data: <code>studies/&lt;name&gt;/results.parquet"
                 "</code> and <code>run.json</code> beside this page.</p></section>"
                 "</body></html>")
    text = "\n".join(parts)
    path = Path(path)
    atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))
    write_json(path.with_name("claims.json"), claims_json(claims), indent=1)
    return path


#: The version of ``claims.json``'s layout (docs/reproducing.md, "claims.json").
CLAIMS_SCHEMA = 2


def claims_json(claims: Sequence[Any]) -> dict[str, Any]:
    """``claims.json``: ``{"schema": 2, "claims": [...]}``, one object a claim.

    Each claim: ``id`` (stable across releases), ``figure``, ``claim`` (the
    one-line summary), ``verdict`` (one of :class:`Verdict`'s texts: the one
    truth, there is no ``holds`` key), ``quote``, ``source``, ``reading``,
    ``numbers`` and ``evidence`` (number keys end with `` [unit]`` when the
    number has one), ``note`` and ``error`` (empty unless the check raised).
    """
    return {"schema": CLAIMS_SCHEMA, "claims": [
        {"id": c.id, "figure": c.figure, "claim": c.text, "verdict": _verdict(c).value,
         "quote": c.quote, "source": c.source, "reading": c.reading, "numbers": c.numbers,
         "evidence": c.evidence, "note": c.note, "error": c.error} for c in claims]}


def read_claims(path: str | Path) -> list[dict[str, Any]]:
    """The claims of a ``claims.json`` written by ``tslip reproduce`` (schema 2).

    Raises a one-line ``ValueError`` for any other layout, naming the schema
    found: the bare list of schema 1 (tslip 0.3.0 and before, with a ``holds`` key) is not read;
    rerun ``tslip reproduce`` (its study caches make that quick).
    """
    import json

    doc = json.loads(Path(path).read_text(encoding="utf-8"))
    schema = doc.get("schema") if isinstance(doc, dict) else 1
    if schema != CLAIMS_SCHEMA or not isinstance(doc.get("claims"), list):
        raise ValueError(f"{path}: claims.json schema {schema!r}, this tslip reads schema "
                         f"{CLAIMS_SCHEMA} only; rerun `tslip reproduce` to rewrite it")
    return list(doc["claims"])


def compute(out_dir: str | Path, *, quick: bool = False, resolution: str | None = None,
            workers: int | None = None, scheduler: str | None = None,
            progress: Callable[[str, str, float], None] | None = None,
            timing: dict[Any, tuple[float, float, Any]] | None = None,
            ) -> tuple[dict[str, Any], list[Any], float, dict[str, str], int]:
    """:func:`tslip.sweeps.reproduce.run_all` with the report's figures drawn as its tasks.

    Returns the data, the claims, the seconds, the figures (PNG data URIs by
    key, for :func:`write_report`) and the worker processes used.
    """
    from ..sweeps.reproduce import run_all

    plots = ReportPlots(out_dir)
    info: dict[str, Any] = {}
    data, claims, seconds = run_all(out_dir, quick=quick, resolution=resolution,
                                    workers=workers, scheduler=scheduler, progress=progress,
                                    timing=timing, extra=plots, info=info)
    return data, claims, seconds, plots.images, int(info["workers"])


def reproduce(out_dir: str | Path, *, quick: bool = False, workers: int | None = None,
              scheduler: str | None = None,
              progress: Callable[[str, str, float], None] | None = None) -> Path:
    """Run every thesis study and figure and write ``out_dir/index.html``.

    See :func:`tslip.sweeps.reproduce.run_all` for the parameters; the
    figures are drawn on the same worker pool as the studies
    (:class:`ReportPlots`), and the page names the worker count used.
    Returns the report's path.
    """
    data, claims, seconds, images, n = compute(out_dir, quick=quick, workers=workers,
                                               scheduler=scheduler, progress=progress)
    path = write_report(Path(out_dir) / "index.html", data, claims, quick=quick,
                        seconds=seconds, workers=n, images=images)
    if progress:
        progress("report", str(path), seconds)
    return path
