"""Design from simulation: the Pareto front of a :class:`~tslip.sweeps.design_spec.DesignSpec`.

The thesis ends (Section 7.8) asking that "the theoretical foundations in
sagittal-plane running should be used to drive design". :func:`design`
does that for the TSLIP: it searches the free parameters of a design spec
for the set of best trade-offs (the Pareto front) between its objectives.

Each candidate design is evaluated by the same analyses as a study point:
the gait search at the spec's speed and touch-down angle
(:func:`tslip.find_gait`, which solves ``alpha_r`` and a controller's
reference), the Floquet multipliers (:func:`tslip.floquet`) and, for the
robustness objectives, the first-failure limits (:func:`tslip.robustness`,
``n_steps`` strides). A candidate without a converged gait, or with an
unstable one (:attr:`tslip.Floquet.stability`: a non-trivial multiplier
outside the unit circle by more than the neutral band), is *infeasible*:
a constraint of the search, never a penalty added to an objective. The
constraint value orders infeasible candidates (no gait: 1; an unstable gait:
``1 - 1/|lambda|``, below 1) so the search moves towards stable ones.

The search is NSGA-II (Deb et al. 2002) from ``pymoo``, an optional extra
(``pip install 'tslip[design]'``), on the variables scaled to ``[0, 1]``, run
one generation at a time through its ask-and-tell interface. Each
generation's missing evaluations run as tasks on the worker pool or a Dask
cluster (:func:`tslip.sweeps._schedule.run_tasks`); the front is the set of
non-dominated feasible designs among *all* evaluations, not only the last
generation.

Resume: every evaluation is appended, as one JSON line of plain data, to
``evaluations.jsonl`` in the output folder, keyed by the candidate's values
and the code hash of the analyses. A rerun with the same spec asks the
seeded search for the same candidates, finds their evaluations there and
computes only the missing ones, so an interrupted and resumed search gives
the identical set of designs. A torn last line (a killed write) is ignored
and recomputed; a changed code hash recomputes everything.
"""

from __future__ import annotations

import json
import math
import os
import time
from collections.abc import Callable, Sequence
from contextlib import ExitStack
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .._codehash import code_hash
from .._io import git_hash, write_json, write_table
from .._lines import BOOL, NUMBER, NUMBER_OR_NULL, STRING, ListOf, Schema, read_lines
from .._results import FrameTable, Result, with_units
from .._safefile import folder, open_below
from ..model.units import param_unit
from ._lock import folder_lock
from ._schedule import Task, choose_workers, run_tasks
from .design_spec import OBJECTIVES, DesignSpec

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..gait.fixed_point import Gait
    from ..gait.robustness import Kind

__all__ = ["DesignResult", "budget_note", "check_folder", "design", "evaluate", "pareto_mask",
           "require_pymoo", "store_schema"]

#: ``progress(done, total)``: evaluations finished (cached ones included) of the budget.
Progress = Callable[[int, int], None]
#: Candidates a task evaluates (a worker's share of a generation, at most).
_CHUNK = 8
#: Seconds one evaluation costs about (gait search and Floquet; robustness adds ~0.1 s a kind).
_COST = 0.02
_ROBUSTNESS: tuple[Kind, ...] = ("step_down", "push", "pitch_rate")
_STORE = "evaluations.jsonl"
#: Samples of the stance in which the peak leg force is looked for.
_FORCE_SAMPLES = 2000


def code_version() -> str:
    """Hash of the code that evaluates a candidate (this module and what it imports)."""
    return code_hash(__name__)


# ---------------------------------------------------------------------------
# one candidate
# ---------------------------------------------------------------------------


def _peak_leg_force(gait: Gait) -> float:
    """Largest axial leg force ``F_l = F_s - c_l ld`` over the gait's stance [m g].

    ``F_l = F_y sin(beta) - F_x cos(beta)`` (eqs 2.5-2.6 solved for it), from the
    ground forces the kernels record: the one leg force of every spring and thrust.

    Sampled 2000 times a stance: the peak is flat (``dF/dt = 0``), so the sampled
    maximum is within about 1e-9 relative of the true one (the default sampling of
    :func:`tslip.simulate`, about 70 rows a stride, is 4e-7 low on Table 2.1).
    """
    from ..simulation import simulate

    p = gait.params
    df = simulate(p, gait.state, 1, dt=gait.stance_time / _FORCE_SAMPLES).to_dataframe()
    st = df[df["stance"] > 0]
    b = st["beta"].to_numpy()
    force = st["Fy"].to_numpy() * np.sin(b) - st["Fx"].to_numpy() * np.cos(b)
    return float(force.max())


def evaluate(spec: DesignSpec, values: dict[str, float]) -> dict[str, Any]:
    """The objectives of one candidate, or why it is infeasible.

    Returns a row: the variables, each objective of ``spec`` (its value as
    reported: limits as magnitudes; NaN when infeasible), ``feasible``,
    ``violation`` (0 when feasible; see the module docstring) and ``reason``
    (empty when feasible).
    """
    from ..gait import find_gait, floquet, robustness, stride_work

    row: dict[str, Any] = {n: float(values[n]) for n in spec.names}
    row.update(dict.fromkeys(spec.objectives, math.nan))

    def infeasible(violation: float, reason: str) -> dict[str, Any]:
        row.update(feasible=False, violation=violation, reason=reason)
        return row

    params = spec.params_at(values)
    gait = find_gait(params)
    if not gait.converged:
        return infeasible(1.0, f"no gait: {gait.message}")
    f = floquet(gait)
    m = float(f.max_nontrivial)
    if f.stability == "unstable":
        return infeasible(1.0 - 1.0 / m, f"unstable gait: max |lambda| = {m:.4g}")
    found = {"max_multiplier": m, "stance_time": float(gait.stance_time)}
    if "peak_leg_force" in spec.objectives:
        found["peak_leg_force"] = _peak_leg_force(gait)
    if "energy_per_stride" in spec.objectives:
        found["energy_per_stride"] = stride_work(gait).hip
    for kind in _ROBUSTNESS:
        if kind in spec.objectives:
            found[kind] = abs(float(robustness(gait, kind, n_steps=spec.n_steps)))
    row.update({o: found[o] for o in spec.objectives})
    row.update(feasible=True, violation=0.0, reason="")
    return row


def _evaluate_chunk(spec: DesignSpec, xs: list[tuple[float, ...]],
                    tick: Callable[[int], None] | None) -> list[dict[str, Any]]:
    rows = []
    for x in xs:
        rows.append(evaluate(spec, dict(zip(spec.names, x))))
        if tick is not None:
            tick(1)
    return rows


# ---------------------------------------------------------------------------
# the front
# ---------------------------------------------------------------------------


def pareto_mask(costs: np.ndarray) -> np.ndarray:
    """Rows of ``costs`` (n x k, all minimised) that no other row dominates.

    A row dominates another when it is no worse in every column and better in
    one. Equal rows are all kept. Rows with a NaN are never on the front.
    """
    costs = np.asarray(costs, dtype=float)
    ok = ~np.isnan(costs).any(axis=1)
    mask = np.zeros(len(costs), dtype=bool)
    idx = np.flatnonzero(ok)
    # visit in order of the sum: a row can only be dominated by one visited before it
    order = idx[np.lexsort((costs[idx].T[::-1]).tolist() + [costs[idx].sum(axis=1)])]
    front: list[int] = []
    for i in order:
        c = costs[i]
        f = costs[front] if front else np.empty((0, costs.shape[1]))
        if not ((f <= c).all(axis=1) & (f < c).any(axis=1)).any():
            front.append(int(i))
    mask[front] = True
    return mask


def _sign(objective: str) -> float:
    """-1 for an objective whose magnitude is maximised, +1 for a minimised one: the
    objective times this is a cost to minimise."""
    return -1.0 if OBJECTIVES[objective][0] > 0 else 1.0


def _costs(frame: pd.DataFrame, objectives: Sequence[str]) -> np.ndarray:
    """Objectives as costs to minimise (maximised ones negated); NaN where infeasible."""
    cols = [_sign(o) * frame[o].to_numpy(float) for o in objectives]
    c = np.column_stack(cols) if cols else np.empty((len(frame), 0))
    c[~frame["feasible"].to_numpy(bool)] = np.nan
    return c


# ---------------------------------------------------------------------------
# the result
# ---------------------------------------------------------------------------


@dataclass(frozen=True, eq=False, repr=False)
class DesignResult(FrameTable, Result):
    """A design search: every evaluated candidate, and its Pareto front.

    Attributes
    ----------
    spec : DesignSpec
    frame : pandas.DataFrame
        One row per evaluation in the order the search asked for them:
        ``generation``, the variables, the objectives, ``feasible``,
        ``violation``, ``reason``, ``front`` (on the Pareto front).
    meta : dict
        Provenance: seconds, evaluations computed and reused, code hash.
    """

    spec: DesignSpec
    frame: pd.DataFrame
    meta: dict[str, Any] = field(default_factory=dict)

    def _repr_fields(self) -> dict[str, Any]:
        f = self.frame
        return {"name": self.spec.name, "evaluations": len(f),
                "feasible": int(f["feasible"].sum()), "front": int(f["front"].sum())}

    def _units(self) -> dict[str, str]:
        return {"generation": "-", "feasible": "-", "violation": "-", "reason": "-",
                "front": "-", **{n: param_unit(n) or "-" for n in self.spec.names},
                **{o: OBJECTIVES[o][1] for o in self.spec.objectives}}

    @property
    def front(self) -> pd.DataFrame:
        """The Pareto-optimal designs, sorted by the first objective (units in ``attrs``)."""
        f = self.frame[self.frame["front"]]
        f = f.drop_duplicates(subset=list(self.spec.names)).sort_values(self.spec.objectives[0])
        return with_units(f.drop(columns=["front", "violation", "reason"]).reset_index(drop=True),
                          self._units())

    def to_dataframe(self) -> pd.DataFrame:
        """Every evaluation (see :attr:`frame`), with units."""
        return with_units(self.frame.copy(), self._units())

    def gait(self, i: int) -> Gait:
        """The periodic gait of front design ``i`` (recomputed; deterministic)."""
        return _front_gait(self.spec, self.front.iloc[int(i)])

    def plot(self, ax: Axes | None = None) -> Figure:
        """The first two objectives of every feasible design, the front highlighted."""
        from ..plotting.design import plot_design

        return plot_design(self, ax)


# ---------------------------------------------------------------------------
# the store of evaluations
# ---------------------------------------------------------------------------


def store_schema(spec: DesignSpec) -> Schema:
    """A line of ``evaluations.jsonl``: the code hash, the candidate's values and its row
    (the variables, the objectives (``null`` where not finite), ``feasible``,
    ``violation``, ``reason``)."""
    row = {**dict.fromkeys(spec.names, NUMBER), **dict.fromkeys(spec.objectives, NUMBER_OR_NULL),
           "feasible": BOOL, "violation": NUMBER, "reason": STRING}
    return Schema({"code": STRING, "x": ListOf(NUMBER, len(spec.names)), "row": Schema(row)})


class _Store:
    """Evaluations as JSON lines: ``{"code": ..., "x": [...], "row": {...}}``.

    Plain data, read by the package's one strict reader
    (:func:`tslip._lines.read_lines`, schema :func:`store_schema`; no NaN literals in
    the text: non-finite numbers are written as ``null``). Lines of other code are
    ignored; a bad line (another shape, a wrong type, not JSON or UTF-8, too deep) is
    ignored with one warning naming the file and line, its candidate evaluated again;
    a torn last line (no newline: a killed write) is cut off the file, so the next
    evaluation appends on a line of its own. The file is opened without following a
    link (:mod:`tslip._safefile`): a link is refused, never written through.
    """

    def __init__(self, path: Path | None, code: str, spec: DesignSpec) -> None:
        self.path, self.code = path, code
        self.rows: dict[tuple[float, ...], dict[str, Any]] = {}
        if path is None:
            return
        recs = read_lines(path.parent, path, store_schema(spec), repair=True,
                          skip=lambda rec: isinstance(rec, dict) and rec.get("code") != code,
                          what=("its candidate is evaluated again",
                                "their candidates are evaluated again"))
        for rec in recs:
            row = {k: (math.nan if v is None else v) for k, v in rec["row"].items()}
            self.rows[tuple(float(v) for v in rec["x"])] = row

    def add(self, x: tuple[float, ...], row: dict[str, Any]) -> None:
        self.rows[x] = row
        if self.path is None:
            return
        clean = {k: (None if isinstance(v, float) and not math.isfinite(v) else v)
                 for k, v in row.items()}
        line = json.dumps({"code": self.code, "x": list(x), "row": clean}, allow_nan=False)
        fd = open_below(self.path.parent, self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT)
        try:
            view = memoryview((line + "\n").encode("utf-8"))
            while view:  # one write a line
                view = view[os.write(fd, view):]
        finally:
            os.close(fd)


# ---------------------------------------------------------------------------
# the search
# ---------------------------------------------------------------------------


def require_pymoo() -> None:
    """Raise the one-line ``ValueError`` of a missing ``design`` extra (pymoo), if it is."""
    try:
        import pymoo.algorithms.moo.nsga2  # noqa: F401
        import pymoo.core.problem  # noqa: F401
    except ImportError:
        raise ValueError("tslip design needs pymoo: pip install 'tslip[design]'") from None


def budget_note(spec: DesignSpec) -> str | None:
    """A line saying how the budget was raised to whole generations, or None if it was not."""
    used = spec.generations * spec.population
    if used == spec.budget:
        return None
    if spec.budget < spec.population:
        return (f"budget {spec.budget} is below the population {spec.population}: raised to "
                f"one generation ({used} evaluations)")
    return (f"budget {spec.budget} is not a whole number of generations of {spec.population}: "
            f"raised to {spec.generations} generations ({used} evaluations)")


def check_folder(out: Path) -> None:
    """Refuse (:class:`tslip._safefile.UnsafePath`) an output folder whose
    ``evaluations.jsonl`` or ``gaits/`` is a link, before any work (the CLI, before its bar)."""
    try:
        os.close(open_below(out, out / _STORE, os.O_RDONLY))
    except FileNotFoundError:
        pass
    try:
        folder(out, out / "gaits", create=False)
    except FileNotFoundError:
        pass


def _nsga2(spec: DesignSpec) -> Any:
    require_pymoo()
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.core.problem import Problem

    n = len(spec.variables)
    problem = Problem(n_var=n, n_obj=len(spec.objectives), n_ieq_constr=1,
                      xl=np.zeros(n), xu=np.ones(n))
    algorithm = NSGA2(pop_size=int(spec.population))
    algorithm.setup(problem, seed=int(spec.seed), termination=("n_gen", spec.generations))
    return algorithm


def design(
    spec: DesignSpec,
    out_dir: str | Path | None = None,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: Progress | None = None,
) -> DesignResult:
    """Search the Pareto front of a design spec (see the module docstring).

    Parameters
    ----------
    spec : DesignSpec
        Free variables with bounds, fixed parameters, objectives, budget.
    out_dir : str or Path, optional
        Folder of the results (``evaluations.jsonl``, ``designs.parquet``,
        ``front.csv``, ``run.json``); a rerun resumes from it.
    workers : int, optional
        Worker processes (default: the machine's cores, fewer for small work).
    scheduler : str, optional
        Address of a Dask cluster to evaluate on instead of local workers.
    progress : callable, optional
        ``progress(done, total)`` after each generation.

    Returns
    -------
    DesignResult

    Raises
    ------
    ValueError
        Without pymoo installed (the ``design`` extra).
    """
    algorithm = _nsga2(spec)
    out = None if out_dir is None else Path(out_dir)
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        check_folder(out)
    code = code_version()
    lo = np.array([v.lower for v in spec.variables])
    span = np.array([v.upper for v in spec.variables]) - lo
    rows: list[dict[str, Any]] = []
    state: dict[str, Any] = {"gen": 0, "pop": None, "xs": [], "computed": 0}
    total = spec.generations * spec.population
    t0 = time.perf_counter()

    def tell() -> None:
        pop, xs = state["pop"], state["xs"]
        gen_rows = [dict(store.rows[x], generation=state["gen"]) for x in xs]
        rows.extend(gen_rows)
        f = np.array([[_sign(o) * r[o] if r["feasible"] else 0.0 for o in spec.objectives]
                      for r in gen_rows])
        pop.set("F", f)
        pop.set("G", np.array([[r["violation"]] for r in gen_rows]))
        algorithm.tell(infills=pop)
        state["gen"] += 1
        if progress is not None:
            progress(len(rows), total)

    def advance() -> list[Task]:
        """Ask for generations until one needs evaluations: their tasks ([] when done)."""
        while state["gen"] < spec.generations:
            pop = algorithm.ask()
            u = np.clip(pop.get("X"), 0.0, 1.0)
            xs = [tuple(float(v) for v in lo + ui * span) for ui in u]
            state.update(pop=pop, xs=xs)
            missing = list(dict.fromkeys(x for x in xs if x not in store.rows))
            if missing:
                state["missing"] = len(missing)
                return [Task(key=("design", state["gen"], i), fn=_evaluate_chunk,
                             args=(spec, missing[i:i + _CHUNK]), cost=_COST * _CHUNK)
                        for i in range(0, len(missing), _CHUNK)]
            tell()
        return []

    def on_done(task: Task, result: list[dict[str, Any]]) -> list[Task]:
        for x, row in zip(task.args[1], result):
            store.add(x, row)
        state["computed"] += len(result)
        state["missing"] -= len(result)
        if state["missing"]:
            return []
        tell()
        return advance()

    with ExitStack() as stack:
        if out is not None:
            stack.enter_context(folder_lock(out))  # one run writes a folder at a time
        store = _Store(None if out is None else out / _STORE, code, spec)
        first = advance()
        if first:
            n = choose_workers(_COST * total, workers, width=len(first))
            run_tasks(first, on_done, workers=n, scheduler=scheduler)
        frame = _frame(spec, rows)
        meta = {"seconds": time.perf_counter() - t0, "computed": state["computed"],
                "reused": len(rows) - state["computed"], "code": code, "git": git_hash()}
        result = DesignResult(spec, frame, meta)
        if out is not None:
            _write(result, out)
    return result


def _front_gait(spec: DesignSpec, row: pd.Series) -> Gait:
    """The periodic gait of a design (a row with the variables), found again."""
    from ..gait import find_gait

    return find_gait(spec.params_at({n: float(row[n]) for n in spec.names}))


def _frame(spec: DesignSpec, rows: list[dict[str, Any]]) -> pd.DataFrame:
    import pandas as pd

    cols = ["generation", *spec.names, *spec.objectives, "feasible", "violation", "reason"]
    frame = pd.DataFrame(rows, columns=cols)
    frame["feasible"] = frame["feasible"].astype(bool)
    frame["front"] = pareto_mask(_costs(frame, spec.objectives))
    return frame


def _write(result: DesignResult, out: Path) -> None:
    """The tables (all designs, the front), the front's gaits and the run record."""
    result.save(out / "designs.parquet")
    front = result.front
    write_table(front, out / "front.csv")  # atomic: a link there is replaced, not written
    gaits = folder(out, out / "gaits")  # a link there is refused
    for i, (_, row) in enumerate(front.iterrows()):
        _front_gait(result.spec, row).save(gaits / f"front-{i:03d}.json")
    write_json(out / "run.json", {"spec": result.spec.to_dict(), **result.meta,
                                  "evaluations": len(result.frame),
                                  "front": len(front)})
