"""Timing verdicts of the paper reproductions: judged only when the measured difference stands
out of the repeats' spread and the times are long enough (ssrlab.experiments.timing_doubt)."""

import pytest

from ssrlab import experiments
from ssrlab.experiments import MIN_JUDGED_MS, TOO_SMALL, target_verdict, timing_doubt


def row(ms, iqr, repeats=5, key="time_frame_ms"):
    return {"repeats": repeats, key: ms, key + "_iqr": iqr}


def test_a_clear_difference_with_enough_repeats_is_judged():
    assert timing_doubt([row(10.0, 0.5), row(20.0, 0.5)], "time_frame_ms", pairwise=True) is None
    assert timing_doubt([row(10.0, 0.5), row(15.0, 0.5), row(20.0, 0.4)], "time_frame_ms") is None


def test_one_timed_run_is_too_small_to_judge():
    why = timing_doubt([row(10.0, None, repeats=1), row(20.0, None, repeats=1)], "time_frame_ms", pairwise=True)
    assert why and "1 timed run" in why


def test_a_difference_within_the_spread_is_too_small_to_judge():
    why = timing_doubt([row(10.0, 2.0), row(12.0, 1.5)], "time_frame_ms", pairwise=True)
    assert why and "spread" in why
    why = timing_doubt([row(10.0, 2.0), row(11.0, 2.0), row(12.0, 2.0)], "time_frame_ms")
    assert why and "spread" in why


def test_times_below_the_minimum_are_too_small_to_judge():
    why = timing_doubt([row(MIN_JUDGED_MS / 4, 0.0), row(MIN_JUDGED_MS * 10, 0.0)], "time_frame_ms", pairwise=True)
    assert why and "below" in why


def test_summed_columns_add_their_spreads():
    a = {"repeats": 5, "x_ms": 5.0, "x_ms_iqr": 1.0, "y_ms": 5.0, "y_ms_iqr": 1.0}
    b = {"repeats": 5, "x_ms": 6.0, "x_ms_iqr": 1.0, "y_ms": 7.0, "y_ms_iqr": 1.0}
    # 10 vs 13 ms: 3 ms apart, within the summed IQRs 2 + 2 ms.
    assert timing_doubt([a, b], ("x_ms", "y_ms"), pairwise=True)
    assert timing_doubt([a, b], ("x_ms",), pairwise=True)  # 1 ms apart, spread 2 ms
    b["y_ms"] = 12.0
    assert timing_doubt([a, b], ("x_ms", "y_ms"), pairwise=True) is None


def test_judged_verdict_states_the_reason():
    ours, verdict = experiments._judged("x 2.0", "agree", [None, "1 timed run(s)"])
    assert verdict == TOO_SMALL and TOO_SMALL in ours and "1 timed run" in ours
    assert experiments._judged("x", "agree", [None]) == ("x", "agree")


def test_a_target_is_met_or_missed_only_by_the_middle_half_of_the_repeats():
    assert target_verdict([1.7, 1.8, 1.9, 1.85, 1.75], "<=", 2.0) == "met"
    assert target_verdict([2.1, 2.2, 2.15, 2.3, 2.05], "<=", 2.0) == "not met"
    assert target_verdict([0.27, 0.26, 0.3, 0.28], ">=", 0.25) == "met"
    assert target_verdict([0.2, 0.22, 0.21, 0.23], ">=", 0.25) == "not met"
    # One outlier on the good side does not make a target met, nor one on the bad side missed.
    assert target_verdict([2.1, 2.2, 1.5, 2.15, 2.05], "<=", 2.0) == "not met"
    assert target_verdict([1.7, 1.8, 2.9, 1.85, 1.75], "<=", 2.0) == "met"
    why = target_verdict([1.9, 2.1, 1.95, 2.05, 2.0], "<=", 2.0)
    assert why.startswith(TOO_SMALL) and "straddles" in why
    assert target_verdict([1.0, 1.1], "<=", 2.0).startswith(TOO_SMALL)
    assert target_verdict([1.0, float("nan"), 1.1], "<=", 2.0).startswith(TOO_SMALL)
    with pytest.raises(ValueError, match="op"):
        target_verdict([1.0, 1.0, 1.0], "<", 2.0)
