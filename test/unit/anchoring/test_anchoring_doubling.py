"""When evidence has doubled: the counts at which an identity is judged again."""

from __future__ import annotations

import pytest

from merlin2_sailor.anchoring.doubling import doubled


@pytest.mark.parametrize("unit", [1, 2, 3, 5])
def test_the_unit_and_each_doubling_of_it_and_nothing_between(unit: int) -> None:
    judged = [count for count in range(200) if doubled(count, unit)]
    assert judged == [unit * 2**power for power in range(8) if unit * 2**power < 200]


def test_no_unit_no_judgement() -> None:
    assert not any(doubled(count, unit) for count in range(20) for unit in (0, -3))
