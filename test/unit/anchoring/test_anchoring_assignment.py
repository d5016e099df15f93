"""assign(): Hungarian on the table, threshold, gated pairs; tracker-id evidence."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from merlin2_sailor.anchoring import assign
from merlin2_sailor.anchoring.assignment import apply_tracker_continuity, tracker_continuations
from merlin2_sailor.errors import InvalidInputError

GATED = -1.0


def pairs(assignment):
    return {tuple(match) for match in assignment.matches.tolist()}


def test_best_total_is_chosen_and_the_rest_unmatched():
    table = np.array([[0.9, 0.8, 0.0], [0.85, 0.1, 0.0]])
    assignment = assign(table, 0.5)
    assert pairs(assignment) == {(0, 1), (1, 0)}
    assert assignment.unmatched_percepts.tolist() == [] and assignment.unmatched_anchors.tolist() == [2]


def test_pairs_below_threshold_are_not_matches():
    assignment = assign(np.array([[0.49, 0.2], [0.1, 0.3]]), 0.5)
    assert assignment.matches.shape == (0, 2)
    assert assignment.unmatched_percepts.tolist() == [0, 1] and assignment.unmatched_anchors.tolist() == [0, 1]


def test_threshold_is_inclusive():
    assert pairs(assign(np.array([[0.5]]), 0.5)) == {(0, 0)}


def test_a_rejected_pair_never_displaces_an_acceptable_one():
    # literal Hungarian (maximise the sum, then threshold) would pick (0,1)+(1,0) = 1.0 and keep
    # only (1,0); accepting (0,0) alone is better: percept 0 reacquires its obvious anchor
    table = np.array([[0.95, 0.45], [0.55, GATED]])
    assignment = assign(table, 0.5)
    assert pairs(assignment) == {(0, 0)}
    assert assignment.unmatched_percepts.tolist() == [1]


def test_gated_pairs_are_never_matched():
    assignment = assign(np.full((3, 2), GATED), 0.5)
    assert assignment.matches.shape == (0, 2)


def test_empty_tables():
    for shape in ((0, 3), (3, 0), (0, 0)):
        assignment = assign(np.zeros(shape), 0.5)
        assert assignment.matches.shape == (0, 2)
        assert len(assignment.unmatched_percepts) == shape[0] and len(assignment.unmatched_anchors) == shape[1]


def test_bad_inputs_are_refused():
    with pytest.raises(InvalidInputError, match="threshold"):
        assign(np.zeros((1, 1)), 0.0)
    with pytest.raises(InvalidInputError, match="2-D"):
        assign(np.zeros(3), 0.5)
    with pytest.raises(InvalidInputError, match="NaN"):
        assign(np.array([[np.nan]]), 0.5)


@settings(max_examples=60, deadline=None)
@given(arrays(np.float64, st.tuples(st.integers(1, 5), st.integers(1, 5)), elements=st.floats(0.0, 1.0)))
def test_assignment_is_a_maximum_weight_matching_of_acceptable_pairs(table):
    from itertools import permutations

    assignment = assign(table, 0.5)
    rows, columns = table.shape
    matched = assignment.matches
    assert len(set(matched[:, 0])) == len(matched) and len(set(matched[:, 1])) == len(matched)
    assert np.all(table[matched[:, 0], matched[:, 1]] >= 0.5)
    # The weight of an acceptable pair is its log-odds over the threshold's (0 at 0.5).
    clipped = np.clip(table, 1e-6, 1.0 - 1e-6)
    log_odds = np.log(clipped / (1.0 - clipped))
    total = log_odds[matched[:, 0], matched[:, 1]].sum()
    best = 0.0  # brute force over every partial matching (tables are tiny)
    padded = np.where(table >= 0.5, log_odds, 0.0)
    size = max(rows, columns)
    square = np.zeros((size, size))
    square[:rows, :columns] = padded
    for permutation in permutations(range(size)):
        best = max(best, square[np.arange(size), permutation].sum())
    assert total == pytest.approx(best)
    assert sorted([*matched[:, 0], *assignment.unmatched_percepts]) == list(range(rows))
    assert sorted([*matched[:, 1], *assignment.unmatched_anchors]) == list(range(columns))


def test_one_near_certain_pair_beats_two_middling_ones_that_slide_a_row_along():
    # Two books 0.18 m apart: the percept of the known one sits on its anchor (0.999); the other
    # percept is a book never seen, beside it. Handing each percept to the neighbour's anchor
    # scores more in sum (0.865 + 0.91 against 0.999 + 0.65) but is far less probable.
    table = np.array([[0.865, 0.999],
                      [0.65, 0.91]])
    assignment = assign(table, 0.5)
    assert {tuple(pair) for pair in assignment.matches.tolist()} == {(0, 1), (1, 0)}
    assert float(table[0, 0] + table[1, 1]) > float(table[0, 1] + table[1, 0])  # what a sum of scores would pick


def test_a_pair_at_the_threshold_is_still_taken():
    assignment = assign(np.array([[0.5, 0.2]]), 0.5)
    assert assignment.matches.tolist() == [[0, 0]]


def test_tracker_continuations_need_equal_non_empty_ids():
    continues = tracker_continuations(np.array(["3", "", "8"], dtype=object), np.array(["3", "", "9"], dtype=object))
    assert continues.tolist() == [[True, False, False], [False, False, False], [False, False, False]]


def test_tracker_continuity_raises_same_class_pairs_only():
    table = np.array([[0.1, 0.2]])
    continues = np.array([[True, True]])
    same_class = np.array([[True, False]])
    raised = apply_tracker_continuity(table, continues, same_class, 0.9)
    assert raised.tolist() == [[0.9, 0.2]]
    assert apply_tracker_continuity(np.array([[0.95]]), continues[:, :1], same_class[:, :1], 0.9).tolist() == [[0.95]]
