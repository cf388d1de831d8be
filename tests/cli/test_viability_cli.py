"""``tslip viability SPEC.toml``: progress, resume, bad input, and 2 workers == 1."""

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from tslip.cli.main import app
from tslip.gait.viability import Viability
from tslip.sweeps import viability as sv

runner = CliRunner()

SPEC = """
name = "tiny"
preset = "slip"
energy = 2.6
rule = "{rule}"

[[state]]
name = "y"
from = 0.9
to = 2.2
points = 12

[action]
name = "alpha_r"
from = 1.0
to = 1.45
points = 20
"""


@pytest.fixture
def spec(tmp_path, monkeypatch):
    monkeypatch.setattr(sv, "CHUNK_CELLS", 100)  # 12 x 20 cells in chunks of 5 states: 3
    path = tmp_path / "spec.toml"
    path.write_text(SPEC.format(rule="bracket"))
    return path


def _run(*args):
    return runner.invoke(app, ["viability", *[str(a) for a in args]])


def _same(a: Viability, b: Viability) -> None:
    assert a.map.next.tobytes() == b.map.next.tobytes()
    assert np.array_equal(a.map.status, b.map.status)
    assert np.array_equal(a.q, b.q) and np.array_equal(a.s, b.s) and a.sweeps == b.sweeps


def test_runs_shows_progress_and_writes_the_result(spec, tmp_path):
    out = tmp_path / "out"
    res = _run(spec, "--out", out, "--workers", "1", "--plot")
    assert res.exit_code == 0, res.output
    assert "viability tiny" in res.stderr and "240/240" in res.stderr
    assert "240 cells" in res.stdout and "viable" in res.stdout
    v = Viability.load(out / "results.parquet")
    assert v.map.shape == (12, 20) and v.q.any()
    meta = json.loads((out / "run.json").read_text())
    assert meta["cells"] == 240 and meta["computed"] == 240 and meta["cached"] == 0
    assert (out / "viability.png").read_bytes()[:4] == b"\x89PNG"
    assert len(list((out / "cache").glob("*.npz"))) == 3
    again = _run(spec, "--out", out)  # finished: every chunk from the cache
    assert again.exit_code == 0
    assert json.loads((out / "run.json").read_text())["cached"] == 240
    _same(Viability.load(out / "results.parquet"), v)


def test_interrupted_run_resumes_to_the_same_result(spec, tmp_path, monkeypatch):
    ref = tmp_path / "ref"
    assert _run(spec, "--out", ref, "--workers", "1").exit_code == 0
    calls = {"n": 0}
    real = sv._chunk_task

    def stop_on_the_second(*args):
        calls["n"] += 1
        if calls["n"] == 2:
            raise KeyboardInterrupt
        return real(*args)

    out = tmp_path / "out"
    monkeypatch.setattr(sv, "_chunk_task", stop_on_the_second)
    res = _run(spec, "--out", out, "--workers", "1")
    assert res.exit_code == 130
    assert res.stderr.strip().splitlines()[-1] == ("100 of 240 cells saved; rerun the same "
                                                   "command to resume")
    assert "Traceback" not in res.output
    monkeypatch.setattr(sv, "_chunk_task", real)
    res = _run(spec, "--out", out, "--workers", "1")
    assert res.exit_code == 0, res.output
    meta = json.loads((out / "run.json").read_text())
    assert meta["cached"] == 100 and meta["computed"] == 140
    _same(Viability.load(out / "results.parquet"), Viability.load(ref / "results.parquet"))


def test_two_workers_give_the_bytes_of_one(spec, tmp_path):
    one, two = tmp_path / "one", tmp_path / "two"
    assert _run(spec, "--out", one, "--workers", "1").exit_code == 0
    res = _run(spec, "--out", two, "--workers", "2")
    assert res.exit_code == 0, res.output
    assert json.loads((two / "run.json").read_text())["workers"] == 2
    _same(Viability.load(one / "results.parquet"), Viability.load(two / "results.parquet"))
    for f in (one / "cache").glob("*.npz"):
        assert (two / "cache" / f.name).read_bytes() == f.read_bytes()


@pytest.mark.parametrize(("old", "new", "match"), [
    ("energy = 2.6", "energy = -1.0", r"energy \[MgL\] must be a number in \(0, inf\)"),
    ("energy = 2.6", "energy = 'high'", r"energy \[MgL\] must be a number"),
    ('rule = "bracket"', 'rule = "closest"', r"rule must be one of \['bracket', 'nearest', "
     r"'vibly'\], got 'closest'"),
    ('name = "y"', 'name = "xd"', "unknown apex variable 'xd'"),
    ("to = 2.2", "to = 2.7", r"states\['y'\] must stay below 2.6"),
    ("points = 20", "points = 0", r"\[action\] alpha_r: points must be an integer"),
    ('name = "alpha_r"', 'name = "stiffness"', "unknown parameter 'stiffness'"),
    ("preset = \"slip\"", "preset = \"slip\"\nwarp = 1", "unknown key 'warp'"),
    ('name = "tiny"', 'name = ".."', r"viability name must match \^\[A-Za-z0-9\]"),
    ('name = "tiny"', 'name = "a/b"', r"viability name must match \^\[A-Za-z0-9\]"),
])
def test_a_bad_spec_value_is_one_line_naming_the_field(tmp_path, old, new, match):
    path = tmp_path / "bad.toml"
    text = SPEC.format(rule="bracket")
    assert old in text
    path.write_text(text.replace(old, new, 1))
    res = _run(path, "--out", tmp_path / "out")
    assert res.exit_code == 2, res.output
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), res.stderr
    import re

    assert re.search(match, lines[0]), lines[0]
    assert not (tmp_path / "out" / "run.json").exists()


def test_rule_vibly_from_the_spec_or_the_option_reuses_the_cached_map(spec, tmp_path):
    out = tmp_path / "out"
    assert _run(spec, "--out", out, "--workers", "1").exit_code == 0
    bracket = Viability.load(out / "results.parquet")
    res = _run(spec, "--out", out, "--rule", "vibly")
    assert res.exit_code == 0, res.output
    meta = json.loads((out / "run.json").read_text())
    assert meta["cached"] == 240 and meta["spec"]["rule"] == "vibly"
    by_option = Viability.load(out / "results.parquet")
    assert by_option.rule == "vibly" and by_option.map.next.tobytes() == bracket.map.next.tobytes()
    # this grid has successors above its top (y = 2.2): vibly's rule keeps more pairs
    assert by_option.q.sum() > bracket.q.sum()
    path = tmp_path / "vibly.toml"
    path.write_text(SPEC.format(rule="vibly"))
    assert _run(path, "--out", tmp_path / "spec", "--workers", "1").exit_code == 0
    _same(Viability.load(tmp_path / "spec" / "results.parquet"), by_option)


def test_a_bad_rule_option_is_one_line(spec, tmp_path):
    res = _run(spec, "--out", tmp_path / "out", "--rule", "closest")
    assert res.exit_code == 2, res.output
    lines = res.stderr.strip().splitlines()
    assert lines == ["error: rule must be one of ['bracket', 'nearest', 'vibly'], got 'closest'"]
    assert not (tmp_path / "out" / "run.json").exists()


def test_a_dot_dot_name_writes_nothing_without_out(tmp_path, monkeypatch):
    """Without --out the map goes to viability/<name>: ".." would be the current folder."""
    work = tmp_path / "work"
    work.mkdir()
    path = tmp_path / "spec.toml"
    path.write_text(SPEC.format(rule="bracket").replace('name = "tiny"', 'name = ".."'))
    monkeypatch.chdir(work)
    res = _run(path)
    assert res.exit_code == 2, res.output
    assert res.stderr.strip().startswith("error: viability name must match")
    assert list(work.iterdir()) == [] and sorted(p.name for p in tmp_path.iterdir()) == \
        ["spec.toml", "work"]


def test_scheduler_option_runs_on_a_dask_cluster(spec, tmp_path):
    """--scheduler ADDRESS: the chunks on a (local) Dask cluster, the bytes of the pool."""
    from dask.distributed import LocalCluster

    one = tmp_path / "one"
    assert _run(spec, "--out", one, "--workers", "1").exit_code == 0
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                      dashboard_address=None) as cluster:
        res = _run(spec, "--out", tmp_path / "d", "--scheduler", cluster.scheduler_address)
        worker = next(iter(cluster.scheduler.workers))  # a Dask server, not a scheduler
        refused = _run(spec, "--out", tmp_path / "w", "--scheduler", worker)
    assert refused.exit_code == 2 and not (tmp_path / "w").exists(), refused.output
    assert f"--scheduler {worker!r} is not a Dask scheduler's address (it answered as " \
        "'Worker')" in refused.stderr, refused.output
    assert res.exit_code == 0, res.output
    assert "240/240" in res.stderr
    _same(Viability.load(one / "results.parquet"), Viability.load(tmp_path / "d" /
                                                                  "results.parquet"))
    meta = json.loads((tmp_path / "d" / "run.json").read_text())
    assert meta["scheduler"] == cluster.scheduler_address and meta["computed"] == 240
