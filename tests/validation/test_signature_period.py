"""The impact signature's misfit reads one period around the impact: a neighbouring impact that falls inside
the window at high speed, and wanders there with the recording's speed, does not count; the event itself does."""
import numpy as np

from bearing_lab.validation.recording_case import declared_fault
from bearing_lab.validation.signature import Signature, misfit


def _sig(next_at_ms, decay=1.0, period=None):
    t = np.arange(-0.002, 0.006, 1 / 20000.0)
    env = np.where(t >= 0, np.exp(-t / (decay * 4e-4)), 0.0) + 1e-3
    env = env + np.where(t >= next_at_ms * 1e-3, np.exp(-(t - next_at_ms * 1e-3) / 4e-4), 0.0)
    return Signature(t, env, 50, (1000.0, 5000.0), period)


def test_the_next_impact_beyond_the_period_window_is_not_compared():
    p = 5.43e-3
    a, b = _sig(5.43, period=p), _sig(5.60, period=p)        # the same event, the next impact 0.17 ms apart
    assert misfit(a, b, level_weight=0)["score_db"] < 1e-9
    a0, b0 = _sig(5.43), _sig(5.60)                          # without the period the whole window counts
    assert misfit(a0, b0, level_weight=0)["score_db"] > 1.0


def test_a_different_event_inside_the_period_still_misfits():
    p = 5.43e-3
    a, b = _sig(5.43, period=p), _sig(5.43, decay=2.0, period=p)
    assert misfit(a, b, level_weight=0)["score_db"] > 1.0


class _Case:
    def __init__(self, defects):
        self.data = {"defect": defects}


def test_declared_fault_of_a_case():
    assert declared_fault(_Case([{"race": "outer"}])) == "bpfo"
    assert declared_fault(_Case([{"race": "inner"}, {"race": "inner"}])) == "bpfi"
    assert declared_fault(_Case([{"race": "outer"}, {"race": "inner"}])) is None
    assert declared_fault(_Case([{"race": "ball"}])) is None
    assert declared_fault(_Case([])) is None
