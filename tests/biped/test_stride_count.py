"""Biped strides are counted right touch-down to right touch-down; scuffs are not strides."""

import numpy as np
import pytest

from tslip.biped import BipedParams, BipedState, simulate
from tslip.biped.simulate import BipedEvent, count_strides, default_min_contact

MIN = 0.08


def _ev(*pairs):
    return [BipedEvent(t, kind, 0.0, 0.0) for t, kind in pairs]


#: A run that starts at a right touch-down: one full right contact, a left
#: step, a right scuff of 0.3 ms, then a real right contact.
BASE = [(0.6, "liftoff_R"), (0.9, "touchdown_L"), (1.4, "liftoff_L"),
        (1.5, "touchdown_R"), (2.05, "liftoff_R")]
SCUFF = [(2.3, "touchdown_R"), (2.3003, "liftoff_R")]
LEFT = [(2.4, "touchdown_L"), (2.9, "liftoff_L")]
RIGHT = [(3.1, "touchdown_R"), (3.65, "liftoff_R")]


def test_a_right_contact_is_a_stride():
    assert count_strides(_ev(*BASE), t_end=2.2, fell=True, min_contact=MIN) == 1
    assert count_strides(_ev(*BASE, *RIGHT), t_end=3.7, fell=True, min_contact=MIN) == 2


def test_a_scuff_is_not_a_stride():
    base = count_strides(_ev(*BASE, *RIGHT), t_end=3.7, fell=True, min_contact=MIN)
    events = sorted(BASE + SCUFF + RIGHT)
    assert count_strides(_ev(*events), t_end=3.7, fell=True, min_contact=MIN) == base
    # ... unless the minimum is below its 0.3 ms
    assert count_strides(_ev(*events), t_end=3.7, fell=True, min_contact=1e-4) == base + 1


def test_a_left_stride_is_not_counted():
    events = sorted(BASE + LEFT + RIGHT)
    assert count_strides(_ev(*events), t_end=3.7, fell=True, min_contact=MIN) == 2
    # a long left stance still on when the run ends is not a (right) stride
    events = _ev(*BASE, (2.4, "touchdown_L"))
    assert count_strides(events, t_end=2.9, fell=True, min_contact=MIN) == 1


def test_a_contact_open_at_the_end():
    events = _ev(*BASE, (2.3, "touchdown_R"))
    # a fall 10 ms after touching down: not a stride; a fall after a long contact: a stride
    assert count_strides(events, t_end=2.31, fell=True, min_contact=MIN) == 1
    assert count_strides(events, t_end=2.6, fell=True, min_contact=MIN) == 2
    # the run stopped at the requested touch-down (no fall): it counts
    assert count_strides(events, t_end=2.3, fell=False, min_contact=MIN) == 2


@pytest.mark.parametrize("bad", [-0.1, float("nan"), float("inf")])
def test_min_contact_is_checked(bad):
    with pytest.raises(ValueError, match="min_contact"):
        count_strides([], t_end=1.0, fell=False, min_contact=bad)


def test_table_e2_run_counts_contacts_of_the_recorded_trajectory():
    p = BipedParams()
    run = simulate(p, BipedState.thesis(), 20)
    mc = default_min_contact(p)
    assert mc == pytest.approx(0.1 * p.d * p.T)
    # independent count from the recorded contact flag: right contact intervals
    on = run["contact_R"] > 0.5
    t = run.time
    starts = np.flatnonzero(on[1:] & ~on[:-1]) + 1
    ends = np.flatnonzero(~on[1:] & on[:-1]) + 1
    durations = [(t[ends[ends > s][0]] if np.any(ends > s) else t[-1]) - t[s] for s in starts]
    assert min(durations) < 1e-2  # this run has a scuff ...
    assert run.count_strides() == sum(d >= mc for d in durations)
    assert run.count_strides() < run.n_steps  # ... which the kernel counted as a stride
    assert run.count_strides(0.0) == run.n_steps
