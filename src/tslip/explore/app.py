"""The explorer's page: one Bokeh document per browser tab.

Controls change the parameters; each change asks for a new gait (in a worker
thread) and the page draws it, its Floquet multipliers, then the robustness
limits ("updating" meanwhile) and the runner after the chosen disturbance.
A newer change makes the older work stop at its next step (a generation
counter). Every callback is guarded: an exception is logged and shown in the
page, and the server goes on; a refused input (a ValueError: a value out of
range, a retraction stop the gait search refuses) is shown as its message and
logged in one line. The work runs in daemon threads and the limits in a worker
process that dies with the server (:mod:`.workers`).

Over 600 lines: one concept, the explorer's page: controls, updates and plots of one document.
"""

from __future__ import annotations

import functools
import html
import logging
import math
import threading
import weakref
from collections.abc import Callable
from typing import Any

import numpy as np
from bokeh.document import Document
from bokeh.layouts import column, row
from bokeh.models import ColumnDataSource, CustomJS, LinearColorMapper, Range1d, TapTool
from bokeh.models.annotations import ColorBar, Label
from bokeh.models.widgets import Button, Div, Select, Slider, Spinner, Toggle
from bokeh.palettes import Viridis256
from bokeh.plotting import figure

from ..model.parameters import Params, preset
from . import compute, workers
from .state import (
    CLOCKS,
    CONTROLS,
    DISTURBANCES,
    FRACTION,
    GAINS,
    PRESETS,
    STOP,
    ExploreState,
    check_fraction,
    control_for,
)

__all__ = ["make_document", "COMPILING", "kernels_cold", "close_pages"]

log = logging.getLogger("tslip.explore")

#: The status line while numba compiles the kernels of a cold cache.
COMPILING = "compiling kernels (first run): the first gait takes about a minute"
#: Set once a gait has been computed in this process: the kernels are loaded.
_WARM = threading.Event()


def kernels_cold() -> bool:
    """True if the TSLIP's kernels are not in numba's cache yet (the first run compiles them)."""
    if _WARM.is_set():
        return False
    try:
        from .. import _kernel_cache
        from ..sweeps._warmup import cache_dirs

        return bool(_kernel_cache.missing_families(cache_dirs(("simulation",)),
                                                   _kernel_cache.sources_hash()))
    except (OSError, AttributeError, ImportError):
        return False


#: The pages open in this process (:func:`close_pages`).
_PAGES: weakref.WeakSet[Explorer] = weakref.WeakSet()


def close_pages() -> None:
    """Stop every page's work (the server is stopping)."""
    for page in list(_PAGES):
        page.close()


#: The retraction stop's choices: none (``alpha_stop = None``), or at the slider's angle.
STOP_CHOICES = {"off": "no stop", "on": "stop at alpha_stop"}


def _stop_value(p: Params) -> float:
    """The stop slider's value: the stop, or (none) 0.3 rad beyond ``alpha_r``, in range."""
    value = p.alpha_stop if p.alpha_stop is not None else p.alpha_r + 0.3
    return min(max(value, 0.01), math.pi - 0.01)


def _all_gains() -> list[str]:
    return list(dict.fromkeys(c.name for g in GAINS.values() for c in g))


class Explorer:
    """The widgets, plots and workers of one page."""

    def __init__(self, doc: Document, state: ExploreState, errors: list[str]) -> None:
        self.doc = doc
        self.generation = 0
        self.lock = threading.Lock()
        self.gait_pool = workers.Lane("tslip-gait")
        self.limit_pool = workers.Lane("tslip-limits")
        self.map_pool = workers.Lane("tslip-map")
        _PAGES.add(self)
        self.map_cancel = threading.Event()
        self.solved: compute.Solved | None = None
        self.limits: dict[str, float] | None = None
        self.loading = False  # while widgets are set from a state, do not ask per widget
        self._build(state)
        self.request()
        self.show_errors(errors)  # the URL's refused entries stay until the next change

    # -- layout --------------------------------------------------------------
    def _build(self, state: ExploreState) -> None:
        p = state.params
        self.status = Div(text="computing the first gait", name="status")
        self.error = Div(text="", name="error", styles={"color": "#b00020"})
        self.preset = Select(title="preset", value=state.preset, options=_options(PRESETS),
                             name="preset")
        self.controller = Select(title="hip controller", value=p.controller.name,
                                 options=_options(GAINS), name="controller")
        self.clock = Select(title="retraction clock", value=p.retraction, options=_options(CLOCKS),
                            name="retraction")
        self.stop = Select(title="retraction stop (Section 7.5)",
                           value="off" if p.alpha_stop is None else "on",
                           options=_options(STOP_CHOICES.items()), name="stop")
        self.stop_angle = self._slider(STOP.name, _stop_value(p))
        self.stop_angle.visible = p.alpha_stop is not None
        self.sliders: dict[str, Slider] = {}
        for c in CONTROLS:
            self.sliders[c.name] = self._slider(c.name, float(getattr(p, c.name)))
        for name in _all_gains():
            value = getattr(p.controller, name, control_for(name).start)
            self.sliders[name] = self._slider(name, float(value))
        self.kind = Select(title="disturbance at the 2nd touch-down", value=state.disturbance,
                           options=_options(DISTURBANCES), name="disturbance")
        self.fraction = Slider(title="magnitude [fraction of its limit]", start=FRACTION[0],
                               end=FRACTION[1], step=0.05, value=state.fraction, name="fraction")
        self.link = Div(text="", name="permalink")
        replace_url = CustomJS(args={"div": self.link}, code=_REPLACE_URL)
        self.link.js_on_change("text", replace_url)
        self.doc.js_on_event("document_ready", replace_url)
        self.preset.on_change("value", self._guard(self._on_preset))
        self.stop_angle.on_change("value", self._guard(self._on_control))
        for w in (self.controller, self.clock, self.stop, self.kind):
            w.on_change("value", self._guard(self._on_select))
        for s in self.sliders.values():
            s.on_change("value", self._guard(self._on_control))
        self.fraction.on_change("value", self._guard(self._on_fraction))
        self._show_gains(p.controller.name)

        # one source a plot (a change is a message): the stance samples are the rows
        # whose "stance_y" is not NaN, the trivial multipliers those whose "triv_re" is not
        self.gait_src = ColumnDataSource({"x": [], "y": [], "stance_y": []}, name="gait_source")
        self.pose_src = ColumnDataSource({"xs": [], "ys": []})
        self.gait_fig = figure(title="periodic gait (2 strides)", width=560, height=260,
                               x_axis_label="x [L]", y_axis_label="y [L]", match_aspect=True,
                               name="gait_plot")
        self.gait_fig.line("x", "y", source=self.gait_src, line_width=2, legend_label="CoM")
        self.gait_fig.scatter("x", "stance_y", source=self.gait_src, size=3, color="#d95f02",
                              legend_label="CoM in stance")
        self.gait_fig.multi_line("xs", "ys", source=self.pose_src, color="black", line_width=2)
        self.gait_fig.legend.location = "bottom_right"

        cx, cy = compute.unit_circle()
        self.mult_src = ColumnDataSource({k: [] for k in ("re", "im", "triv_re", "triv_im",
                                                          "abs", "kind")})
        self.mult_fig = figure(title="Floquet multipliers", width=300, height=300,
                               x_range=Range1d(start=-1.3, end=1.3),
                               y_range=Range1d(start=-1.3, end=1.3), match_aspect=True,
                               x_axis_label="Re", y_axis_label="Im", name="multiplier_plot",
                               tooltips=[("|lambda|", "@abs"), ("", "@kind")])
        self.mult_fig.line(cx, cy, color="grey")
        self.mult_fig.scatter("re", "im", source=self.mult_src, size=9,
                              legend_label="non-trivial")
        self.mult_fig.scatter("triv_re", "triv_im", source=self.mult_src, size=14, marker="x",
                              color="#d95f02", line_width=2, legend_label="trivial")
        self.mult_fig.legend.location = "bottom_left"
        self.mult_text = Div(text="", name="multipliers")
        self.limit_text = Div(text="", name="limits")

        self._build_runner()
        self._build_map()
        controls = column(self.status, self.error, self.preset, self.controller, self.clock,
                          *self.sliders.values(), self.stop, self.stop_angle, self.kind,
                          self.fraction, self.link, width=330)
        plots = column(row(self.gait_fig, column(self.mult_fig, self.mult_text)),
                       self.limit_text, self.runner_panel, self.map_panel)
        self.doc.add_root(row(controls, plots))
        self.doc.title = "tslip explore"

    def _slider(self, name: str, value: float) -> Slider:
        c = control_for(name)
        lo, hi = c.span(value)
        return Slider(title=c.title, start=lo, end=hi, step=c.step, value=value, name=name)

    def _build_runner(self) -> None:
        """The runner's animation: frames sent once a run, played in the browser."""
        self.frames_src = ColumnDataSource({k: [] for k in _FRAME_KEYS}, name="runner_frames")
        self.path_src = ColumnDataSource({"x": [], "y": []})
        self.ground_src = ColumnDataSource({"x": [], "y": []}, name="runner_ground")
        self.leg_src = ColumnDataSource({"x": [], "y": []}, name="runner_leg")
        self.axis_src = ColumnDataSource({"x": [], "y": []}, name="runner_axis")
        self.grf_src = ColumnDataSource({"x": [], "y": []}, name="runner_grf")
        self.body_src = ColumnDataSource({"x": [], "y": [], "w": [], "h": [], "angle": []})
        self.joint_src = ColumnDataSource({"x": [], "y": [], "fill": []}, name="runner_pose")
        fig = figure(title="runner after the disturbance", width=860, height=260,
                     x_axis_label="x [L]", y_axis_label="y [L]", match_aspect=True,
                     name="runner_plot")
        fig.line("x", "y", source=self.ground_src, color="black", line_width=1.5)
        fig.line("x", "y", source=self.path_src, color="#1f77b4", alpha=0.4)
        fig.line("x", "y", source=self.leg_src, color="#262626", line_width=1.6)
        fig.ellipse("x", "y", width="w", height="h", angle="angle", source=self.body_src,
                    fill_color="#9ecae1", line_color="#08519c", line_width=1.5)
        fig.line("x", "y", source=self.axis_src, color="#08519c", line_width=1.2)
        fig.line("x", "y", source=self.grf_src, color="#e34a33", alpha=0.6, line_width=3)
        fig.scatter("x", "y", source=self.joint_src, size=8, fill_color="fill",
                    line_color="black")
        self.clock_label = Label(x=8, y=8, x_units="screen", y_units="screen", text="",
                                 text_font="monospace", text_font_size="11px")
        fig.add_layout(self.clock_label)
        self.play = Toggle(label="play / pause", active=True, name="runner_play", width=110)
        self.frame = Slider(title="frame", start=0, end=1, step=1, value=0, name="runner_frame",
                            width=600)
        player = CustomJS(args={
            "frames": self.frames_src, "leg": self.leg_src, "axis": self.axis_src,
            "grf": self.grf_src, "body": self.body_src, "joints": self.joint_src,
            "label": self.clock_label, "slider": self.frame, "toggle": self.play,
            "fps": compute.FPS}, code=_PLAYER)
        self.frames_src.js_on_change("data", player)
        self.frame.js_on_change("value", player)
        self.play.js_on_change("active", player)
        self.strip_fig = fig
        self.strip_text = Div(text="", name="runner")
        self.runner_panel = column(fig, row(self.play, self.frame), self.strip_text)

    def _build_map(self) -> None:
        names = [c.name for c in CONTROLS] + _all_gains()
        self.map_x = Select(title="map x", value="r", options=_options(names), name="map_x")
        self.map_y = Select(title="map y", value="k", options=_options(names), name="map_y")
        self.map_n = Spinner(title="points per axis", low=2, high=30, step=1, value=8,
                             name="map_points")
        self.map_go = Button(label="compute map", name="map_go", button_type="primary")
        self.map_stop = Button(label="cancel", name="map_stop", disabled=True)
        self.map_status = Div(text="", name="map_status")
        self.map_src = ColumnDataSource({"x": [], "y": [], "w": [], "h": [], "lam": []},
                                        name="map_source")
        mapper = LinearColorMapper(palette=Viridis256, low=0.0, high=1.2, nan_color="lightgrey")
        self.map_fig = figure(title="largest non-trivial |multiplier| (grey: no gait)",
                              width=460, height=380, tools=[TapTool(mode="replace"), "reset"],
                              name="map_plot",
                              tooltips=[("x", "@x"), ("y", "@y"), ("|lambda|", "@lam")])
        self.map_fig.rect("x", "y", "w", "h", source=self.map_src,
                          fill_color={"field": "lam", "transform": mapper}, line_color=None)
        self.map_fig.add_layout(ColorBar(color_mapper=mapper), "right")
        self.map_go.on_click(self._guard(self._on_map))
        self.map_stop.on_click(self._guard(lambda: self.map_cancel.set()))
        self.map_src.selected.on_change("indices", self._guard(self._on_cell))
        self.map_panel = row(column(self.map_x, self.map_y, self.map_n, self.map_go,
                                    self.map_stop, self.map_status, width=200), self.map_fig)

    def close(self) -> None:
        """Stop this page's work (its tab closed)."""
        with self.lock:
            self.generation += 1
        self.map_cancel.set()
        for pool in (self.gait_pool, self.limit_pool, self.map_pool):
            pool.shutdown()

    # -- guards and threads --------------------------------------------------
    def _guard(self, fn: Callable[..., None]) -> Callable[..., None]:
        @functools.wraps(fn)
        def run(*args: Any) -> None:
            try:
                fn(*args)
            except Exception as exc:  # noqa: BLE001 - shown in the page, logged, server goes on
                self.show_errors([_report(exc)], logged=True)
        return run

    def _post(self, fn: Callable[..., None], *args: Any) -> None:
        """Run ``fn(*args)`` on the document's thread (guarded)."""
        self.doc.add_next_tick_callback(functools.partial(self._guard(fn), *args))

    def _background(self, pool: workers.Lane, fn: Callable[..., None], *args: Any) -> None:
        def run() -> None:
            try:
                fn(*args)
            except Exception as exc:  # noqa: BLE001 - shown in the page, logged
                self._post(self.show_errors, [_report(exc)], True)
        pool.submit(run)

    def show_errors(self, errors: list[str], logged: bool = False) -> None:
        """Show ``errors`` in the page (and log them, one line each, unless ``logged``);
        an empty list clears the line."""
        for e in errors if not logged else ():
            log.warning("tslip explore: %s", e)
        self.error.text = "<br>".join(html.escape(e) for e in errors)

    # -- state ---------------------------------------------------------------
    def params(self) -> Params:
        """The parameters the controls hold, through the validators of :class:`Params`."""
        base = preset(self.preset.value)
        data: dict[str, Any] = {c.name: float(self.sliders[c.name].value) for c in CONTROLS}
        data["retraction"] = self.clock.value
        if self.stop.value == "on":
            data["alpha_stop"] = float(self.stop_angle.value)
        ctrl: dict[str, Any] = {"type": self.controller.value}
        if self.controller.value == base.controller.name:
            ctrl = base.controller.to_dict()  # keeps its solved reference as the guess
        for c in GAINS[self.controller.value]:
            ctrl[c.name] = float(self.sliders[c.name].value)
        data["controller"] = ctrl
        return Params.from_dict(data, base=base)

    def state(self) -> ExploreState:
        return ExploreState(self.preset.value, self.params(), self.kind.value,
                            float(self.fraction.value))

    def _show_gains(self, kind: str) -> None:
        shown = {c.name for c in GAINS[kind]}
        for name in _all_gains():
            self.sliders[name].visible = name in shown

    def load(self, state: ExploreState) -> None:
        """Set every control from ``state`` and ask for its gait once."""
        self.loading = True
        try:
            p = state.params
            self.preset.value = state.preset
            self.controller.value = p.controller.name
            self.clock.value = p.retraction
            self.stop.value = "off" if p.alpha_stop is None else "on"
            self._set_slider(STOP.name, _stop_value(p))
            self.stop_angle.visible = p.alpha_stop is not None
            for c in CONTROLS:
                self._set_slider(c.name, float(getattr(p, c.name)))
            for c in GAINS[p.controller.name]:
                self._set_slider(c.name, float(getattr(p.controller, c.name)))
            self._show_gains(p.controller.name)
        finally:
            self.loading = False
        self.request()

    def _set_slider(self, name: str, value: float) -> None:
        s = self.stop_angle if name == STOP.name else self.sliders[name]
        s.start, s.end = control_for(name).span(value)
        s.value = value

    # -- callbacks -------------------------------------------------------------
    def _on_preset(self, attr: str, old: Any, new: Any) -> None:
        if not self.loading:
            self.load(ExploreState(new, preset(new), self.kind.value, float(self.fraction.value)))

    def _on_select(self, attr: str, old: Any, new: Any) -> None:
        if self.loading:
            return
        self._show_gains(self.controller.value)
        self.stop_angle.visible = self.stop.value == "on"
        self.request()

    def _on_control(self, attr: str, old: Any, new: Any) -> None:
        if not self.loading:
            self.request()

    def _on_fraction(self, attr: str, old: Any, new: Any) -> None:
        check_fraction(float(new))  # a crafted message can send any number
        self.show_errors([])
        self._update_link()
        if self.solved is not None and self.solved.gait is not None and self.limits:
            self._background(self.limit_pool, self._runner, self.generation, self.solved.gait,
                             self.limits)

    def request(self) -> None:
        """Ask for the gait of the controls' parameters; older requests stop."""
        try:
            params = self.params()
        except ValueError as exc:
            self.show_errors([str(exc)])
            return
        self.show_errors([])
        with self.lock:
            self.generation += 1
            gen = self.generation
        if not _WARM.is_set():
            self.status.text = "computing the first gait"
        # nothing else is sent now: each change is a message the page lays out before the
        # next, so the gait's draw sends the permalink and "updating" along with the gait
        self._background(self.gait_pool, self._solve, gen, params)

    def _update_link(self) -> None:
        try:
            q = self.state().query()
        except ValueError:
            return
        self.link.text = (f'<a href="?{html.escape(q)}">permalink</a> &middot; export: '
                          f'<a href="/export/params.toml?{html.escape(q)}" download>'
                          'parameters (TOML)</a>, '
                          f'<a href="/export/trajectory.parquet?{html.escape(q)}" download>'
                          'trajectory (parquet)</a>')

    def stale(self, gen: int) -> bool:
        return gen != self.generation

    # -- work in the threads, drawing on the document's thread -----------------
    def _solve(self, gen: int, params: Params) -> None:
        if self.stale(gen):
            return
        if not _WARM.is_set() and kernels_cold():
            self._post(setattr, self.status, "text", COMPILING)
        solved = compute.solve(params)
        _WARM.set()
        if self.stale(gen):
            return
        self._post(self._draw_gait, gen, solved)

    def _limits(self, gen: int, gait: Any) -> None:
        lim = compute.limits(gait, stop=lambda: self.stale(gen), run=workers.limit)
        if lim is None or self.stale(gen):
            return
        self._post(self._draw_limits, gen, lim)
        self._runner(gen, gait, lim)

    def _runner(self, gen: int, gait: Any, lim: dict[str, float]) -> None:
        kind, frac = self.kind.value, check_fraction(float(self.fraction.value))
        mag = compute.magnitude(lim[kind], frac)
        traj = compute.disturbed_run(gait, kind, mag)
        frames, ground = compute.runner_frames(traj), compute.ground(traj)
        if not self.stale(gen):
            self._post(self._draw_runner, gen, traj, frames, ground, kind, mag)

    def _draw_gait(self, gen: int, solved: compute.Solved) -> None:
        if self.stale(gen):
            return
        self.solved, self.limits = solved, None
        if solved.refused:  # the search refused the parameters: said in the error line
            self.show_errors([solved.message])
        if not solved.ok:
            for src in (self.gait_src, self.mult_src, self.pose_src, self.frames_src,
                        self.path_src, self.ground_src):
                src.data = {str(k): [] for k in src.data}
            self.mult_text.text = "no gait"
            self.limit_text.text = "robustness limits: no gait"
            self.strip_text.text = ""
            self._draw_status(solved.message)
            return
        assert solved.trajectory is not None and solved.floquet is not None
        assert solved.gait is not None
        tr, fl = solved.trajectory, solved.floquet
        stance = tr["stance"] > 0.5
        self.gait_src.data = {"x": tr["x"], "y": tr["y"],
                              "stance_y": np.where(stance, tr["y"], np.nan)}
        self.pose_src.data = _poses(tr, np.flatnonzero(np.diff(tr["stance"]) > 0.5) + 1)
        m = np.asarray(fl.multipliers)
        kinds = list(fl.trivial_kinds) or [""] * len(m)
        t = np.asarray(fl.trivial, dtype=bool)
        nan = np.full(len(m), np.nan)
        self.mult_src.data = {"re": np.where(t, nan, m.real), "im": np.where(t, nan, m.imag),
                              "triv_re": np.where(t, m.real, nan),
                              "triv_im": np.where(t, m.imag, nan), "abs": np.abs(m),
                              "kind": [(k or "trivial") if tt else "non-trivial"
                                       for k, tt in zip(kinds, t, strict=True)]}
        mags = ", ".join(f"{abs(x):.4f}" + (" (trivial)" if tt else "") for x, tt in zip(m, t,
                                                                                        strict=True))
        self.mult_text.text = (f"|multipliers|: {mags}<br>largest non-trivial "
                               f"{fl.max_nontrivial:.4f}: {fl.stability} (gait residual "
                               f"{solved.gait.residual:.1e})")
        if fl.stable:
            self.limit_text.text = "robustness limits: updating"
            # asked for here, after the gait is drawn: callbacks posted before the page's
            # session exists run in any order (Bokeh keeps them in a set), and the limits
            # drawn before their gait would be hidden by its "updating"
            self._background(self.limit_pool, self._limits, gen, solved.gait)
        else:
            self.limit_text.text = "robustness limits: none (the gait is unstable)"
            self.strip_text.text = ""
        self._draw_status(solved.message)

    def _draw_status(self, message: str) -> None:
        """The status line (unchanged while gaits are found: a change is a message) and link."""
        self.status.text = message
        self._update_link()

    def _draw_limits(self, gen: int, lim: dict[str, float]) -> None:
        if self.stale(gen):
            return
        self.limits = lim
        units = {"step_down": "L", "push": "g^1/2 L^1/2", "pitch_rate": "rad g^1/2 L^-1/2"}
        self.limit_text.text = "robustness limits (25 strides): " + ", ".join(
            f"{k} {v:.4g} [{units[k]}]" for k, v in lim.items())

    def _draw_runner(self, gen: int, tr: Any, frames: dict[str, Any],
                     ground: tuple[np.ndarray, np.ndarray], kind: str, mag: float) -> None:
        if self.stale(gen):
            return
        self.ground_src.data = {"x": ground[0], "y": ground[1]}
        self.path_src.data = {"x": tr["x"], "y": tr["y"]}
        self.frames_src.data = frames  # the page plays them (_PLAYER)
        self.strip_text.text = (f"{kind} of {mag:.4g} at the 2nd touch-down: "
                                f"{len(tr.steps)} strides, {tr.status.name}; "
                                f"{len(frames['t'])} frames at {compute.FPS:g} per second, "
                                f"{compute.SPEED:g} x real time for a 1 m leg")

    # -- the stability map ------------------------------------------------------
    def _on_map(self) -> None:
        x, y = self.map_x.value, self.map_y.value
        if x == y:
            raise ValueError("map x and map y must be two different parameters")
        for name in (x, y):
            if not self.sliders[name].visible:
                raise ValueError(f"{name} is not a gain of the {self.controller.value} "
                                 "controller; map one of the controls shown")
        n = int(self.map_n.value or 2)
        spans = []
        for name in (x, y):  # around the current value: a quarter of the slider's span
            s = self.sliders[name]
            half = 0.125 * (s.end - s.start)
            lo = min(max(s.start, s.value - half), s.end - 2 * half)
            spans.append((name, float(lo), float(lo + 2 * half)))
        self.map_cancel.clear()
        self.map_go.disabled, self.map_stop.disabled = True, False
        self.map_status.text = f"map: 0/{n * n} points"
        self._background(self.map_pool, self._map, self.params(), spans[0], spans[1], n)

    def _map(self, params: Params, x: tuple[str, float, float], y: tuple[str, float, float],
             n: int) -> None:
        def progress(done: int, total: int) -> None:
            if self.map_cancel.is_set():
                raise compute.MapCancelled
            self._post(setattr, self.map_status, "text", f"map: {done}/{total} points")

        try:
            res = compute.stability_map(params, x, y, n, progress)
        except compute.MapCancelled:
            self._post(self._map_done, None, x, y, "map: cancelled")
            return
        except Exception:
            self._post(self._map_done, None, x, y, "map: failed (see the error line)")
            raise
        self._post(self._map_done, res, x, y, f"map: {n * n} points done; click a cell")

    def _map_done(self, res: Any, x: tuple[str, float, float], y: tuple[str, float, float],
                  text: str) -> None:
        self.map_go.disabled, self.map_stop.disabled = False, True
        self.map_status.text = text
        if res is None:
            return
        frame = res.frame
        xs = frame[res.spec.axes[1].param].to_numpy(float)
        ys = frame[res.spec.axes[0].param].to_numpy(float)
        lam = frame["max_nontrivial"].to_numpy(float)
        n = len(res.spec.axes[1].values)
        self.map_src.data = {"x": xs, "y": ys, "w": np.full(len(xs), (x[2] - x[1]) / max(n - 1, 1)),
                             "h": np.full(len(xs), (y[2] - y[1]) / max(n - 1, 1)), "lam": lam}
        self.map_fig.xaxis.axis_label = _label(x[0])
        self.map_fig.yaxis.axis_label = _label(y[0])
        self.map_axes = (x[0], y[0])

    def _on_cell(self, attr: str, old: Any, new: list[int]) -> None:
        if not new:
            return
        i = new[0]
        x, y = self.map_axes
        self.loading = True
        try:
            self._set_slider(x, float(self.map_src.data["x"][i]))
            self._set_slider(y, float(self.map_src.data["y"][i]))
        finally:
            self.loading = False
        self.request()


def _report(exc: Exception) -> str:
    """Log ``exc`` and return its text for the page: a refused input (a ValueError) as its
    message in one log line; anything else with its class name, its traceback logged."""
    if isinstance(exc, ValueError):
        log.warning("tslip explore: %s", exc)
        return str(exc)
    log.error("tslip explore: %s", exc, exc_info=exc)
    return f"{type(exc).__name__}: {exc}"


def _options(names: Any) -> list[Any]:
    """A Select's options (Bokeh's stubs want a list of str or pairs)."""
    return list(names)


def _label(name: str) -> str:
    c = control_for(name)
    return f"{name} [{c.unit}]"


def _poses(tr: Any, idx: np.ndarray) -> dict[str, Any]:
    """Leg (foot to hip) and trunk (hip to CoM) lines at the samples ``idx``."""
    xs, ys = [], []
    for i in idx:
        xs += [[tr["foot_x"][i], tr["hip_x"][i]], [tr["hip_x"][i], tr["x"][i]]]
        ys += [[tr["foot_y"][i], tr["hip_y"][i]], [tr["hip_y"][i], tr["y"][i]]]
    return {"xs": xs, "ys": ys}


#: The columns of the runner's frames (:func:`compute.runner_frames`).
_FRAME_KEYS = ("t", "stance", "com_x", "com_y", "hip_x", "hip_y", "foot_x", "foot_y", "centre_x",
               "centre_y", "angle", "body_w", "body_h", "leg_x", "leg_y", "axis_x", "axis_y",
               "grf_x", "grf_y")

#: Plays the runner's frames in the browser: a new run restarts at frame 0, the toggle
#: starts and stops a timer at ``fps`` that steps the frame slider, and the slider shows
#: its frame. The pose sources change in the page only (``sync: false``): a frame costs
#: the server nothing.
_PLAYER = """
const n = frames.get_length() || 0;
const quiet = {sync: false};
function show(i) {
  const d = frames.data;
  if (n === 0) {
    for (const s of [leg, axis, grf, body, joints]) {
      const empty = {};
      for (const k of Object.keys(s.data)) empty[k] = [];
      s.setv({data: empty}, quiet);
    }
    label.setv({text: ''}, quiet);
    return;
  }
  const line = (col) => {  // row i of an (n, m) array, copied element by element: on
    // Bokeh's typed array class (3.9.2) subarray() returns the whole array, every frame
    const a = d[col], m = a.length / n, out = new Array(m);
    for (let j = 0; j < m; j++) out[j] = a[i * m + j];
    return out;
  };
  leg.setv({data: {x: line('leg_x'), y: line('leg_y')}}, quiet);
  axis.setv({data: {x: line('axis_x'), y: line('axis_y')}}, quiet);
  grf.setv({data: {x: line('grf_x'), y: line('grf_y')}}, quiet);
  body.setv({data: {x: [d.centre_x[i]], y: [d.centre_y[i]], w: [d.body_w[i]],
                    h: [d.body_h[i]], angle: [d.angle[i]]}}, quiet);
  joints.setv({data: {x: [d.hip_x[i], d.com_x[i], d.foot_x[i]],
                      y: [d.hip_y[i], d.com_y[i], d.foot_y[i]],
                      fill: ['white', 'black', d.stance[i] > 0.5 ? '#d62728' : 'white']}},
              quiet);
  label.setv({text: `t = ${d.t[i].toFixed(3)} g^-1/2 L^1/2  frame ${i + 1}/${n}  `
                    + (d.stance[i] > 0.5 ? 'stance' : 'flight')}, quiet);
}
if (cb_obj === frames) {
  slider.setv({end: Math.max(n - 1, 1), value: 0}, quiet);
  show(0);
} else if (cb_obj === slider) {
  show(Math.min(Math.max(Math.round(slider.value), 0), Math.max(n - 1, 0)));
}
if (cb_obj === toggle || cb_obj === frames) {
  if (frames._tslip_timer) { clearInterval(frames._tslip_timer); frames._tslip_timer = null; }
  if (toggle.active && n > 0) {
    frames._tslip_timer = setInterval(() => {
      const m = frames.get_length() || 1;
      slider.setv({value: (Math.round(slider.value) + 1) % m}, quiet);
    }, 1000 / fps);
  }
}
"""

#: Keep the address bar on the current state (the permalink's query).
_REPLACE_URL = """
const m = div.text.match(/href="\\?([^"]*)"/);
if (m) { history.replaceState(null, '', '?' + m[1].replace(/&amp;/g, '&')); }
"""


def make_document(doc: Document) -> None:
    """Build the explorer in ``doc`` from its request's URL query (the Bokeh app's entry)."""
    from .state import parse_query

    args: dict[str, str] = {}
    request = getattr(doc.session_context, "request", None)
    if request is not None:
        for k, v in request.arguments.items():
            if k.startswith("bokeh-"):
                continue
            args[k] = v[-1].decode("utf-8", "replace") if v else ""
    state, errors = parse_query(args)
    page = Explorer(doc, state, errors)
    doc.on_session_destroyed(lambda _ctx: page.close())
