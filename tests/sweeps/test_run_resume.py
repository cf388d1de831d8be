"""Resume to the point: an interrupted study recomputes only its missing points and
ends bit-identical to an uninterrupted run; progress advances point by point."""

import pandas as pd
import pytest

import tslip
from tslip.sweeps import Axis, StudySpec, run_study
from tslip.sweeps import point as point_mod
from tslip.sweeps.run import StudyInterrupted, saved_points


def _line_spec():
    # v0 = 1 has no gait: the walk fails there, so the line also has a failure record
    return StudySpec("line", tslip.preset("table2.1"),
                     (Axis("v0", (1.0, 4.0, 4.5, 5.0, 5.5, 6.0)),), analyses=("floquet",))


def _grid_spec():
    return StudySpec("grid", tslip.preset("table2.1-local-velocity"),
                     (Axis("v0", (4.0, 5.0, 6.0)), Axis("k", (20.0, 22.5, 25.0))),
                     analyses=("floquet",))


def _exact(a: pd.DataFrame, b: pd.DataFrame) -> None:
    pd.testing.assert_frame_equal(a.drop(columns="seconds"), b.drop(columns="seconds"),
                                  check_exact=True)


def _interrupt_after(k: int):
    def progress(done, total):
        if done >= k:
            raise KeyboardInterrupt

    return progress


@pytest.mark.parametrize(("make", "k"), [(_line_spec, 3), (_grid_spec, 4)])
def test_interrupted_study_resumes_point_by_point_bit_identical(tmp_path, monkeypatch, make,
                                                                 k):
    spec = make()
    full = run_study(spec, tmp_path / "full", workers=1)
    with pytest.raises(StudyInterrupted) as exc:
        run_study(spec, tmp_path / "cut", workers=1, progress=_interrupt_after(k))
    assert (exc.value.saved, exc.value.total) == (k, spec.n_points)
    assert str(exc.value) == (f"{k} of {spec.n_points} points saved; rerun the same command "
                              "to resume")
    assert saved_points(spec, tmp_path / "cut") == k
    # the resumed run computes only the missing points: count the gait searches
    solved: list[float] = []
    real = point_mod._Line.finish

    def counting(self, i, g, residual, message):
        solved.append(float(self.values[i]))
        return real(self, i, g, residual, message)

    monkeypatch.setattr(point_mod._Line, "finish", counting)
    res = run_study(spec, tmp_path / "cut", workers=1)
    assert res.meta["cached"] == k and res.meta["computed"] == spec.n_points - k
    assert len(solved) == spec.n_points - k
    _exact(full.frame, res.frame)
    _exact(full.frame, pd.read_parquet(tmp_path / "cut" / "results.parquet"))


def test_progress_advances_point_by_point(tmp_path):
    spec = _line_spec()
    seen: list[int] = []
    run_study(spec, tmp_path, workers=1, progress=lambda done, total: seen.append(done))
    assert set(range(spec.n_points + 1)) <= set(seen)
    assert seen == sorted(seen)
