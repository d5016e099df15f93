"""Any text becomes a harmless PDDL name; invalid names are refused with a way out."""

import re

import pytest
from hypothesis import given
from hypothesis import strategies as st

from merlin2_sailor.errors import KnowledgeError
from merlin2_sailor.knowledge.naming import (
    IDENTIFIER_PATTERN,
    RESERVED_WORDS,
    is_identifier,
    require_identifier,
    symbol,
    to_identifier,
)

HOSTILE = [
    ") (:goal (and))",
    "cup)\n(:init (robot_at rb1 wp1)",
    "; comment\ncup",
    "?x - object",
    "(define (domain evil))",
    "cup\x00\x1b[31m",
    "   \t\n  cup   ",
    "CUP--3",
]


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("dining table", "dining_table"),
        ("cup - 3", "cup_3"),
        ("Cup", "cup"),
        ("Café crème", "cafe_creme"),
        ("Ñandú", "nandu"),
        ("ﬁsh", "fish"),  # A ligature, split by compatibility decomposition.
        ("3d printer", "id_3d_printer"),
        ("_private", "private"),
        ("and", "id_and"),
        ("AT", "id_at"),
        ("over all", "over_all"),
        ("teddy_bear", "teddy_bear"),
        ("wp1", "wp1"),
    ],
)
def test_examples(text, expected):
    assert to_identifier(text) == expected


@pytest.mark.parametrize("text", HOSTILE)
def test_hostile_text_becomes_one_plain_token(text):
    name = to_identifier(text)
    assert IDENTIFIER_PATTERN.fullmatch(name)
    assert not set(name) & set("()?;-\n \t:")


@pytest.mark.parametrize("word", sorted(RESERVED_WORDS))
def test_every_reserved_word_is_made_harmless(word):
    name = to_identifier(word)
    assert name != word and is_identifier(name)


@given(st.text(max_size=40))
def test_any_text_is_a_valid_identifier_or_a_clear_error(text):
    try:
        name = to_identifier(text)
    except KnowledgeError as error:
        assert "fallback=" in str(error)
        assert not re.search(r"[A-Za-z0-9]", text)
        return
    assert is_identifier(name)
    assert to_identifier(name) == name


@given(st.text(max_size=40))
def test_a_fallback_always_gives_a_valid_identifier(text):
    assert is_identifier(to_identifier(text, fallback="unknown"))


@pytest.mark.parametrize("text", ["", "   ", "!!!", "杯子", "---"])
def test_text_without_letters_needs_a_fallback(text):
    with pytest.raises(KnowledgeError, match="no ASCII letter or digit"):
        to_identifier(text)
    assert to_identifier(text, fallback="thing") == "thing"


def test_non_text_is_refused():
    with pytest.raises(KnowledgeError, match="pass a string"):
        to_identifier(3)  # type: ignore[arg-type]


def test_require_identifier_suggests_a_repair():
    assert require_identifier("cup_3", "object name") == "cup_3"
    with pytest.raises(KnowledgeError, match=r"invalid object name 'cup - 3'.*'cup_3'"):
        require_identifier("cup - 3", "object name")
    with pytest.raises(KnowledgeError, match=r"PDDL keyword.*'id_and'"):
        require_identifier("and", "predicate name")
    with pytest.raises(KnowledgeError, match="lowercase letters"):
        require_identifier("???", "type name")


@pytest.mark.parametrize(
    ("class_name", "index", "expected"),
    [("cup", 3, "cup_3"), ("dining table", 0, "dining_table_0"), ("3d", 12, "id_3d_12")],
)
def test_symbol(class_name, index, expected):
    assert symbol(class_name, index) == expected


@pytest.mark.parametrize("index", [-1, 1.0, True, "3"])
def test_symbol_needs_a_non_negative_integer(index):
    with pytest.raises(KnowledgeError, match="non-negative integer"):
        symbol("cup", index)
