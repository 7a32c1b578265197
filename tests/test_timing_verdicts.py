"""Timing verdicts of the paper reproductions: judged only when the measured difference stands
out of the repeats' spread and the times are long enough (ssrlab.experiments.timing_doubt)."""

from ssrlab import experiments
from ssrlab.experiments import MIN_JUDGED_MS, TOO_SMALL, timing_doubt


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
