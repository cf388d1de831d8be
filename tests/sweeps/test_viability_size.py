"""A viability grid that does not fit is refused before it is allocated (issue 40): the
estimate of its run's memory, the one-line refusal, the chunks made on demand, and two
``[[state]]`` tables of one variable refused."""

import math

import numpy as np
import pytest

import tslip
from tslip import _checks, _gridsize
from tslip.gait import _viable
from tslip.sweeps import viability as sv
from tslip.sweeps.spec import Axis

HUGE = 100_000


def _grid(n_y: int, n_a: int = 3, third: int | None = None) -> sv.ViabilitySpec:
    states = [Axis("y", tuple(np.linspace(1.0, 1.6, n_y)))]
    if third:
        states += [Axis("phi", tuple(np.linspace(-0.2, 0.2, third))),
                   Axis("phid", tuple(np.linspace(-0.1, 0.1, third)))]
    return sv.ViabilitySpec("g", tslip.preset("slip"), tuple(states),
                            Axis("alpha_r", tuple(np.linspace(1.0, 1.45, n_a))), 2.6)


def test_the_blocks_are_the_iterations_blocks():
    assert _gridsize.BLOCK_ROWS == _viable.CHUNK_ROWS
    assert sv.CHUNK_CELLS == _gridsize.CHUNK_CELLS


def test_chunks_are_made_on_demand_and_are_the_slices_of_the_grid():
    spec = _grid(7, n_a=3, third=3)  # 63 states x 3 actions
    per = sv.CHUNK_CELLS // 3
    expect = [slice(i, min(i + per, 63)) for i in range(0, 63, per)]
    assert list(spec.chunks()) == expect == [spec.chunks()[i] for i in range(len(expect))]
    assert len(spec.chunks()) == 1
    big = _grid(HUGE, third=HUGE)  # 1e15 states: the slices exist only when asked for
    chunks = big.chunks()
    assert len(chunks) == math.ceil(HUGE**3 / (sv.CHUNK_CELLS // 3))
    last = chunks[-1]
    assert last.stop == HUGE**3 and last.stop - last.start == HUGE**3 % 666
    assert chunks[1] == next(x for i, x in enumerate(chunks) if i == 1) == slice(666, 1332)
    # the last chunk's points: the top height and pitch, the last pitch rates
    pts = big.points(last)
    assert pts.shape == (last.stop - last.start, 3)
    assert np.array_equal(pts[-1], [1.6, 0.2, 0.1])
    assert np.allclose(pts[:, 2], np.linspace(-0.1, 0.1, HUGE)[-len(pts):])
    with pytest.raises(IndexError):
        chunks[len(chunks)]


def test_cells_are_counted_without_overflow():
    spec = _grid(HUGE, n_a=HUGE, third=HUGE)
    assert spec.n_cells == HUGE**4 > 2**63  # numpy's int64 product would wrap


def test_a_grid_that_does_not_fit_is_refused_in_one_line(monkeypatch):
    spec = _grid(HUGE, third=HUGE)
    with pytest.raises(ValueError) as exc:
        spec.check_fits()
    msg = str(exc.value)
    assert "\n" not in msg and "3000000000000000 cells" in msg
    assert "100000 x 100000 x 100000 states x 3 actions" in msg
    assert f"{_gridsize._size(_checks.available_memory())[:2]}" in msg
    # the estimate: at least a byte a pair (the viable pairs), 3e15 bytes
    assert spec.memory() >= HUGE**3 * 3 and "PB of memory" in msg
    small = _grid(40, n_a=20)
    small.check_fits()
    monkeypatch.setattr(_gridsize, "available_memory", lambda: small.memory() - 1)
    with pytest.raises(ValueError, match="800 cells .* need about"):
        small.check_fits()
    monkeypatch.setattr(_gridsize, "available_memory", lambda: small.memory())
    small.check_fits()


def test_run_viability_refuses_before_it_makes_its_folder(tmp_path, monkeypatch):
    def computed(*args):  # a run that starts instead of refusing fails here, not hangs
        raise AssertionError("a chunk was computed")

    monkeypatch.setattr(sv, "_chunk_task", computed)
    with pytest.raises(ValueError, match="cells .* of memory"):
        sv.run_viability(_grid(HUGE, third=HUGE), tmp_path / "o", workers=1)
    assert not (tmp_path / "o").exists()


def test_the_estimate_bounds_an_in_memory_runs_arrays(tmp_path):
    """Not stored: the estimate covers the map's arrays and the result's, as numpy counts
    them (``nbytes``) after a real run; stored, it covers the pairs and states held."""
    spec = _grid(30, n_a=10)
    res = sv.run_viability(spec, None, workers=1)
    held = res.map.next.nbytes + res.map.status.nbytes + res.q.nbytes + res.s.nbytes
    assert held <= spec.memory(stored=False)
    assert res.q.nbytes + res.s.nbytes <= spec.memory(stored=True) < spec.memory(stored=False)


def test_two_state_tables_of_one_variable_are_refused(tmp_path):
    y = Axis("y", (1.0, 1.2))
    with pytest.raises(ValueError, match=r"\[\[state\]\] .* different .* 'y' 2 times"):
        sv.ViabilitySpec("g", tslip.preset("slip"), (y, y), Axis("alpha_r", (1.1, 1.2)), 2.6)
    path = tmp_path / "s.toml"
    path.write_text('energy = 2.6\n[[state]]\nname = "y"\nvalues = [1.0, 1.2]\n'
                    '[[state]]\nname = "y"\nvalues = [1.1, 1.3]\n'
                    '[action]\nname = "alpha_r"\nvalues = [1.1, 1.2]\n')
    with pytest.raises(ValueError, match="'y' 2 times"):
        sv.ViabilitySpec.from_toml(path)
