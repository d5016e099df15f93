"""One exception family for the whole project.

Callers catch :class:`SailorError` to handle anything this package raises on purpose, and
the subclasses to react to one kind of failure. Every message says what to do about it, because
the people reading it are robot operators in the middle of a mission, not the authors.
"""


class SailorError(Exception):
    """Base of every error raised deliberately by merlin2_sailor."""


class ConfigurationError(SailorError):
    """A parameter, YAML file or command-line option is missing, malformed or inconsistent."""


class DependencyError(SailorError):
    """An optional dependency (a backend, a store, a model file) is not installed or not found."""


class InvalidInputError(SailorError):
    """Input data (an image, a message, a detection) cannot be used and is dropped."""


class KnowledgeError(SailorError):
    """A knowledge-base operation was rejected (unknown type, wrong arity, store unreachable)."""
