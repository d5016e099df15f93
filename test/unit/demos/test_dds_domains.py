"""Runs of the demo claim DDS domains no other run holds, and give them back when they end."""

from __future__ import annotations

import contextlib
import subprocess
import sys

import pytest

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor_demos.dds_domains import claimed_domain

DOMAINS = range(1, 6)


def test_a_held_domain_is_passed_over_and_free_again_once_released(tmp_path) -> None:
    with claimed_domain(DOMAINS, 2, tmp_path) as first:
        assert first == 3
        with claimed_domain(DOMAINS, 2, tmp_path) as second:
            assert second == 4  # the same start, as two suites' process ids may give
    with claimed_domain(DOMAINS, 2, tmp_path) as again:
        assert again == 3


def test_the_search_wraps_round_and_says_when_every_domain_is_held(tmp_path) -> None:
    with claimed_domain(DOMAINS, 4, tmp_path) as last, claimed_domain(DOMAINS, 4, tmp_path) as wrapped:
        assert (last, wrapped) == (5, 1)
    with contextlib.ExitStack() as every_one:
        for _ in DOMAINS:
            every_one.enter_context(claimed_domain(DOMAINS, 0, tmp_path))
        with pytest.raises(ConfigurationError, match="every DDS domain 1-5 is held"):
            every_one.enter_context(claimed_domain(DOMAINS, 0, tmp_path))


def test_another_process_holding_a_domain_keeps_it_from_this_one(tmp_path) -> None:
    """The case that made duplicates of runs: two suites, two processes."""
    holder = subprocess.Popen(
        [sys.executable, "-c",
         "import sys, pathlib\n"
         "from merlin2_sailor_demos.dds_domains import claimed_domain\n"
         f"with claimed_domain(range(1, 6), 0, pathlib.Path({str(tmp_path)!r})) as domain:\n"
         "    print(domain, flush=True)\n"
         "    sys.stdin.readline()\n"],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "1"
        with claimed_domain(DOMAINS, 0, tmp_path) as mine:
            assert mine == 2
    finally:
        holder.communicate("\n", timeout=30)
    with claimed_domain(DOMAINS, 0, tmp_path) as after:
        assert after == 1  # the holder ended: its lock went with it
