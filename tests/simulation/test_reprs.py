"""Results print as one short line that names what matters, never their arrays."""

from __future__ import annotations

import dataclasses

import pytest

import tslip
from tslip.model.state import TouchdownState


@pytest.fixture(scope="module")
def gait() -> tslip.Gait:
    return tslip.find_gait(tslip.preset("table2.1"))


def _short(text: str) -> None:
    assert "\n" not in text and "array(" not in text and len(text) < 120, text


def test_trajectory_repr(gait: tslip.Gait) -> None:
    traj = tslip.simulate(gait.params, gait.state, 3)
    text = repr(traj)
    _short(text)
    assert text.startswith(f"Trajectory(3 strides, {len(traj.data)} samples, t 0 to ")
    assert f"{traj.time[-1]:.6g}" in text and text.endswith("status OK)")


def test_step_repr(gait: tslip.Gait) -> None:
    res = tslip.step(gait.params, gait.state)
    text = repr(res)
    _short(text)
    assert text.startswith("StepResult(OK, ") and f"{res.stance_time:.6g}" in text


def test_batch_reprs_count_rows_by_status(gait: tslip.Gait) -> None:
    slow = dataclasses.replace(gait.state, xd=0.05, yd=-0.05)  # falls in its first stride
    states: list[TouchdownState] = [gait.state, gait.state, slow]
    run = tslip.run_batch(gait.params, states, 4)
    text = repr(run)
    _short(text)
    fell = tslip.Status(int(run.status[2])).name
    assert fell != "OK"
    assert text == f"BatchRun(3 rows, 4 strides asked; OK 2, {fell} 1)" or \
        text == f"BatchRun(3 rows, 4 strides asked; {fell} 1, OK 2)"
    step = tslip.step_batch(gait.params, [s.section() for s in states])
    _short(repr(step))
    assert repr(step).startswith("BatchStep(3 rows; ") and "OK 2" in repr(step)
