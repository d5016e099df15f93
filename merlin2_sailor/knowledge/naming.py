"""The one place where text becomes a PDDL identifier.

Class names from detectors, waypoint names from maps and words typed by users all end up in PDDL
files that a planner parses. Funnelling every one of them through :func:`to_identifier` means a
single, tested rule decides what a name may look like, so no text can ever break a PDDL file or
inject syntax into it (a class called ``") (:goal (and))"`` becomes an ordinary, harmless name).

The identifiers are deliberately narrower than PDDL allows (``^[a-z][a-z0-9_]*$``: no hyphens, no
upper case) because MERLIN2, KANT and most planners agree on that subset, and a name that means
the same thing everywhere is worth more than the characters it gives up.
"""

import re
import unicodedata

from merlin2_sailor.errors import KnowledgeError

IDENTIFIER_PATTERN = re.compile(r"^[a-z][a-z0-9_]*$")
"""Every identifier this package writes into PDDL matches this pattern."""

PREFIX = "id_"
"""Put before text that cannot stand alone: it starts with a digit or is a PDDL keyword."""

RESERVED_WORDS = frozenset(
    {
        # Section and requirement keywords.
        "define",
        "domain",
        "problem",
        "requirements",
        "types",
        "constants",
        "predicates",
        "functions",
        "action",
        "parameters",
        "duration",
        "condition",
        "precondition",
        "effect",
        "objects",
        "init",
        "goal",
        "metric",
        "derived",
        "constraints",
        # Logical and temporal connectives.
        "and",
        "or",
        "not",
        "imply",
        "either",
        "forall",
        "exists",
        "when",
        "at",
        "over",
        "start",
        "end",
        "all",
        "preference",
        "always",
        "sometime",
        "within",
        # Numeric operators and metrics.
        "increase",
        "decrease",
        "assign",
        "minimize",
        "maximize",
        "number",
    }
)
"""Words a planner may read as syntax rather than as a name, whatever their position."""

_SEPARATOR_RUN = re.compile(r"[^a-z0-9]+")


def is_identifier(text: str) -> bool:
    """Tell whether ``text`` can be written into PDDL as a name exactly as it is."""
    return (
        isinstance(text, str)
        and IDENTIFIER_PATTERN.fullmatch(text) is not None
        and text not in RESERVED_WORDS
    )


def to_identifier(text: str, fallback: str | None = None) -> str:
    """Turn any text into a valid, readable PDDL identifier.

    Accents are dropped ("Café" -> "cafe"), every run of other characters becomes one underscore
    ("cup - 3" -> "cup_3"), and text that starts with a digit or is a PDDL keyword gets
    :data:`PREFIX` ("3d printer" -> "id_3d_printer", "and" -> "id_and"). Distinct texts may
    share an identifier ("Cup" and "cup"); that is intended, since both name the same class.

    Raises:
        KnowledgeError: the text has no letter or digit and no ``fallback`` was given.
    """
    if not isinstance(text, str):
        raise KnowledgeError(
            f"cannot make a PDDL name from {text!r} of type {type(text).__name__}; pass a string"
        )
    decomposed = unicodedata.normalize("NFKD", text)
    without_accents = "".join(
        character for character in decomposed if not unicodedata.combining(character)
    )
    words = _SEPARATOR_RUN.sub("_", without_accents.lower()).strip("_")
    if not words:
        if fallback is None:
            raise KnowledgeError(
                f"cannot make a PDDL name from {text!r}: it has no ASCII letter or digit; "
                "give it a name made of letters, or pass fallback="
            )
        return to_identifier(fallback)
    if not words[0].isalpha() or words in RESERVED_WORDS:
        words = PREFIX + words
    return words


def require_identifier(text: str, role: str) -> str:
    """Return ``text`` unchanged when it is a valid identifier, else explain how to get one.

    The knowledge model rejects invalid names instead of quietly repairing them, because a silent
    repair could merge two different names ("cup-3" and "cup_3") into one object.
    """
    if is_identifier(text):
        return text
    if isinstance(text, str) and text in RESERVED_WORDS:
        reason = "it is a PDDL keyword"
    else:
        reason = "a PDDL name must match ^[a-z][a-z0-9_]*$"
    try:
        hint = f"; use {to_identifier(text)!r} (merlin2_sailor.knowledge.naming.to_identifier)"
    except KnowledgeError:
        hint = "; give it a name made of lowercase letters, digits and underscores"
    raise KnowledgeError(f"invalid {role} {text!r}: {reason}{hint}")


def symbol(class_name: str, index: int) -> str:
    """Name the anchor number ``index`` of a class, e.g. ``symbol("cup", 3) == "cup_3"``.

    The index comes from a persistent counter (the anchoring node's
    :class:`~merlin2_sailor.anchoring.symbols.SymbolCounter`), so the pair never repeats and the
    symbol stays stable for as long as the anchor lives.
    """
    if isinstance(index, bool) or not isinstance(index, int) or index < 0:
        raise KnowledgeError(
            f"symbol index must be a non-negative integer, got {index!r}; "
            "take it from a persistent counter such as the anchoring node's SymbolCounter"
        )
    return f"{to_identifier(class_name)}_{index}"
