"""The in-memory symbol counter."""

from __future__ import annotations

from merlin2_sailor.anchoring import SymbolCounter


def test_counts_per_class_from_one_with_pddl_names():
    counter = SymbolCounter()
    assert [counter("cup"), counter("cup"), counter("Dining Table")] == ["cup_1", "cup_2", "dining_table_1"]


def test_instances_do_not_share_counters():
    first, second = SymbolCounter(), SymbolCounter()
    first("cup")
    assert second("cup") == "cup_1"


def test_note_used_moves_past_restored_symbols():
    counter = SymbolCounter()
    counter.note_used(["cup_7", "cup_3", "dining_table_2", "kitchen", "oddname_"])
    assert counter("cup") == "cup_8"
    assert counter("dining table") == "dining_table_3"
    assert counter("bowl") == "bowl_1"
