from __future__ import annotations

import pytest

from merlin2_sailor.diagnostics.topic_statistics import TopicStatistics


def test_rate_and_age_over_the_window() -> None:
    statistics = TopicStatistics(window_seconds=2.0)
    for index in range(31):  # 30 Hz for one second, each message 10 ms old on arrival
        arrival = 100.0 + index / 30.0
        statistics.record(arrival, stamp_seconds=arrival - 0.010)
    report = statistics.report(now_seconds=101.0)
    assert report.messages == 31
    assert report.rate_hz == pytest.approx(30.0)
    assert report.mean_age_seconds == pytest.approx(0.010)
    assert report.total_messages == 31


def test_old_messages_leave_the_window_but_stay_counted() -> None:
    statistics = TopicStatistics(window_seconds=1.0)
    statistics.record(0.0)
    statistics.record(0.5)
    report = statistics.report(now_seconds=5.0)
    assert (report.messages, report.rate_hz, report.total_messages) == (0, 0.0, 2)
    assert report.mean_age_seconds is None


def test_messages_without_stamps_have_no_age_and_window_must_be_positive() -> None:
    statistics = TopicStatistics()
    statistics.record(1.0, stamp_seconds=None)
    statistics.record(1.1, stamp_seconds=0.0)  # an unset header stamp is not an age
    assert statistics.report(1.1).mean_age_seconds is None
    with pytest.raises(ValueError):
        TopicStatistics(window_seconds=0.0)
