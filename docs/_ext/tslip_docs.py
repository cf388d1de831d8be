"""Pages of the documentation generated from the package itself at build time.

* ``_generated/parameters.md``: the parameter table of :class:`tslip.model.Params`,
  read from its fields' metadata.
* ``_generated/cli.md``: every ``tslip`` command, its usage, arguments and
  options, read from the Typer app (so the reference cannot drift from the CLI).
* ``_generated/verdicts.md``: the verdict table of ``tslip reproduce``, run at
  ``TSLIP_DOCS_RESOLUTION`` (``tiny``, ``quick`` (default) or ``full``) into
  ``docs/_build/reproduce-<resolution>/`` (its study cache makes rebuilds
  fast and is keyed by the code hash), or read from an existing report folder
  given as ``TSLIP_DOCS_REPORT``. The report page itself is copied into the
  site as ``report/index.html``.

A file is rewritten only when its text changes, so an unchanged build stays
incremental.

The two models share their class names (``Trajectory``, ``StepResult``, ...:
docs/model.md, "Vocabulary"), so an unqualified name in a docstring or an
annotation outside ``tslip.biped`` would match both. :func:`_prefer_tslip`
reads it as the TSLIP's; inside ``tslip.biped`` the biped's own name is found
first anyway (Sphinx looks in the current module before anywhere else).
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Any

import typer

DOCS = Path(__file__).resolve().parents[1]
GENERATED = DOCS / "_generated"
RESOLUTIONS = ("tiny", "quick", "full")


def _write(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        path.write_text(text, encoding="utf-8")


# -- CLI reference -------------------------------------------------------------

def _cell(text: str | None) -> str:
    return " ".join((text or "").split()).replace("|", "\\|")


def _param_rows(cmd: Any, ctx: Any) -> list[str]:
    """One table row per argument or option, from the CLI's own help records."""
    rows = []
    for p in cmd.get_params(ctx):
        record = None if getattr(p, "hidden", False) else p.get_help_record(ctx)
        if record is None or p.name == "help":
            continue
        names, help_text = record
        help_text = help_text.replace("\\[", "[")  # Rich markup escapes
        rows.append(f"| `{_cell(names)}` | {p.param_type_name} | {_cell(help_text)} |")
    return rows


def _command_md(cmd: Any, path: list[str], parent: Any) -> list[str]:
    ctx = cmd.context_class(cmd, info_name=path[-1], parent=parent)
    title = " ".join(path)
    out = [f"## `{title}`", "", (cmd.help or "").strip(), ""]
    pieces = " ".join(cmd.collect_usage_pieces(ctx))
    out += ["```text", f"{title} {pieces}".rstrip(), "```", ""]
    rows = _param_rows(cmd, ctx)
    if rows:
        out += ["| name | kind | meaning |", "| --- | --- | --- |", *rows, ""]
    if hasattr(cmd, "list_commands"):
        for name in cmd.list_commands(ctx):
            sub = cmd.get_command(ctx, name)
            if sub is not None and not getattr(sub, "hidden", False):
                out += _command_md(sub, [*path, name], ctx)
    return out


def cli_reference() -> str:
    """Markdown reference of every ``tslip`` command, read from the Typer app."""
    from tslip.cli.main import app

    root = typer.main.get_command(app)
    lines = ["# Command-line reference", "",
             "Generated from the `tslip` command itself when the documentation is built. "
             "Every command exits 0 on success; bad input prints one line `error: ...` "
             "and exits non-zero.", ""]
    ctx = root.context_class(root, info_name="tslip")
    for name in root.list_commands(ctx):
        sub = root.get_command(ctx, name)
        if sub is not None and not getattr(sub, "hidden", False):
            lines += _command_md(sub, ["tslip", name], ctx)
    return "\n".join(lines).rstrip() + "\n"


# -- parameter table ------------------------------------------------------------

def _bound(value: float, open_: bool, lower: bool) -> str:
    """One end of a range in interval notation: ``(0`` or ``inf)``."""
    if lower:
        return "(-inf" if value == float("-inf") else ("(" if open_ else "[") + f"{value:g}"
    return "inf)" if value == float("inf") else f"{value:g}" + (")" if open_ else "]")


def parameter_table() -> str:
    """Markdown table of :class:`tslip.model.Params`, read from its fields' metadata."""
    import dataclasses

    from tslip.model import Params
    from tslip.model.parameters import LEG_RESETS, RETRACTIONS

    def choices(values: tuple[str, ...]) -> str:
        return ", ".join(f'`"{v}"`' for v in values)

    lines = ["| field | symbol | unit | default | range | meaning | source |",
             "| --- | --- | --- | --- | --- | --- | --- |"]
    for f in dataclasses.fields(Params):
        md = f.metadata
        if "lower" not in md:  # not a number field (alpha_stop: below)
            continue
        lo = _bound(md["lower"], md["lower_open"], True)
        hi = _bound(md["upper"], md["upper_open"], False)
        lines.append(f"| `{f.name}` | {md['symbol']} | {md['unit']} | {f.default:g} "
                     f"| {lo}, {hi} | {_cell(md['description'])} | {md['source']} |")
    lines.append("| `controller` | | | `Passive()` | | stance hip controller | Section 2.4 |")
    defaults = {f.name: f.default for f in dataclasses.fields(Params)}
    lines.append(f'| `leg_reset` | | | `"{defaults["leg_reset"]}"` | {choices(LEG_RESETS)} '
                 "| frame of `alpha_r` and `omega_r` | Sections 2.3.2, 7.6 |")
    lines.append(f'| `retraction` | | | `"{defaults["retraction"]}"` | {choices(RETRACTIONS)} '
                 "| start of the retraction clock: lift-off (eq. 2.17) or the flight apex "
                 "(held at `alpha_r` until then) | Section 2.5 |")
    stop = {f.name: f for f in dataclasses.fields(Params)}["alpha_stop"].metadata
    lines.append(f"| `alpha_stop` | {stop['symbol']} | {stop['unit']} | `None` | {stop['range']} "
                 f"| {_cell(stop['description'])} | {stop['source']} |")
    return "\n".join(lines) + "\n"


# -- verdict table ----------------------------------------------------------------

def _report_dir() -> tuple[Path, str]:
    given = os.environ.get("TSLIP_DOCS_REPORT")
    if given:
        path = Path(given)
        if not (path / "claims.json").is_file():
            raise ValueError(f"TSLIP_DOCS_REPORT={given!r} has no claims.json; "
                             "give a folder written by `tslip reproduce`")
        return path, "given"
    res = os.environ.get("TSLIP_DOCS_RESOLUTION", "quick")
    if res not in RESOLUTIONS:
        raise ValueError(f"TSLIP_DOCS_RESOLUTION must be one of {RESOLUTIONS}, got {res!r}")
    out = DOCS / "_build" / f"reproduce-{res}"
    from tslip.plotting.report import write_report
    from tslip.sweeps.reproduce import run_all

    info: dict[str, Any] = {}
    data, claims, seconds = run_all(out, resolution=res, workers=1 if res == "tiny" else None,
                                    info=info)
    write_report(out / "index.html", data, claims, quick=res != "full", seconds=seconds,
                 workers=info["workers"])
    return out, res


def verdict_table(claims: list[dict[str, Any]], resolution: str) -> str:
    """Markdown table of the claims of a schema-2 ``claims.json`` and their verdicts.

    The first line counts the claims and, by name, every verdict (zero included),
    in :class:`tslip.sweeps.claims.Verdict`'s order: the only verdict counts the
    documentation states.
    """
    from tslip.sweeps.claims import Verdict

    counts = ", ".join(f"{sum(c['verdict'] == v for c in claims)} {v.value}" for v in Verdict)
    lines = [f"{len(claims)} claims at **{resolution}** resolution: {counts}.", "",
             "| id | figure | claim | verdict | note |", "| --- | --- | --- | --- | --- |"]
    for c in claims:
        note = c.get("error") or c.get("note") or ""
        lines.append(f"| `{_cell(c['id'])}` | {_cell(c['figure'])} | {_cell(c['claim'])} "
                     f"| {_cell(c['verdict'])} | {_cell(note)} |")
    return "\n".join(lines) + "\n"


def _generate(app: Any, config: Any) -> None:
    from tslip.plotting.report import read_claims

    _write(GENERATED / "cli.md", cli_reference())
    _write(GENERATED / "parameters.md", parameter_table())
    folder, res = _report_dir()
    claims = read_claims(folder / "claims.json")
    _write(GENERATED / "verdicts.md", verdict_table(claims, res))
    report = GENERATED / "extra" / "report"  # html_extra_path: served as report/index.html
    report.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(folder / "index.html", report / "index.html")


# -- gallery: figures the package's plotting functions return ------------------------

_SCRAPED: set[int] = set()


def figure_scraper(block: Any, block_vars: dict[str, Any], gallery_conf: dict[str, Any]) -> str:
    """Save every new :class:`matplotlib.figure.Figure` bound to a name in the example.

    ``tslip.plotting`` builds figures without pyplot (so they are safe in worker
    processes and never open a window), which sphinx-gallery's matplotlib scraper
    does not see; an example binds the returned figure to a name instead.

    It runs before the matplotlib scraper, which saves (and closes) every figure pyplot
    holds: those are marked as seen and left to it, so no figure is saved twice.
    """
    import matplotlib.pyplot as plt
    from matplotlib.figure import Figure
    from sphinx_gallery.scrapers import figure_rst

    _SCRAPED.update(id(plt.figure(num)) for num in plt.get_fignums())
    paths = []
    for value in list(block_vars["example_globals"].values()):
        if isinstance(value, Figure) and id(value) not in _SCRAPED:
            _SCRAPED.add(id(value))
            path = next(block_vars["image_path_iterator"])
            value.savefig(path, dpi=80)
            paths.append(path)
    return figure_rst(paths, gallery_conf["src_dir"])


def _prefer_tslip() -> None:
    """Resolve an unqualified shared class name outside ``tslip.biped`` to the TSLIP's."""
    from sphinx.domains.python import PythonDomain

    find_obj = PythonDomain.find_obj
    if getattr(find_obj, "_tslip", False):
        return

    def find(self: Any, env: Any, modname: Any, classname: Any, name: str, type: Any,
             searchmode: int = 0) -> list[Any]:
        matches = find_obj(self, env, modname, classname, name, type, searchmode)
        if len(matches) > 1 and not str(modname or "").startswith("tslip.biped"):
            tslip_side = [m for m in matches if not m[0].startswith("tslip.biped.")]
            matches = tslip_side or matches
        return matches

    find._tslip = True  # type: ignore[attr-defined]
    PythonDomain.find_obj = find  # type: ignore[method-assign]


def setup(app: Any) -> dict[str, Any]:
    app.connect("config-inited", _generate)  # before html_extra_path is checked
    _prefer_tslip()
    return {"parallel_read_safe": True, "parallel_write_safe": True}
