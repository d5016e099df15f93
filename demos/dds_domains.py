"""DDS domains for runs of the demo that must not hear each other: one lock file per domain.

Two ``sailor demo`` suites on one machine (the rules and the network side by side, say) used to
pick their domains from their process ids, in turn; the two sequences met, and two runs shared a
domain: one run's behaviors node registered its actions in the other's knowledge base, whose
mission then waited for actions that never came and ended as a crash (measured on 5 December
2026: 2 of 30 concurrent runs). A run now holds an exclusive ``flock`` on its domain's file for
as long as it runs; the lock goes with the process, so a run killed mid-way leaves nothing to
clean up. Only runs that claim domains this way are kept apart: a ROS 2 program started by hand
in the same domain is not seen.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import os
import tempfile
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import IO

from merlin2_sailor.errors import ConfigurationError

#: DDS domains runs may use (1-100: the range that is safe on Linux; 0 is left to the user).
DOMAINS = range(1, 101)
#: Where the lock files live: one folder per machine, shared by its users (DDS domains are too).
LOCK_FOLDER = Path(tempfile.gettempdir()) / "sailor-dds-domains"


@contextlib.contextmanager
def claimed_domain(domains: Sequence[int], first: int, folder: Path = LOCK_FOLDER) -> Iterator[int]:
    """Hold the first domain of ``domains``, from index ``first`` on (wrapping round), that no
    other claim holds; released when the block ends.

    Raises:
        ConfigurationError: every domain is held (a message saying so, not a hang).
    """
    folder.mkdir(parents=True, exist_ok=True)
    with contextlib.suppress(OSError):  # another user's folder: theirs to open up
        folder.chmod(0o1777)
    for offset in range(len(domains)):
        domain = domains[(first + offset) % len(domains)]
        handle = _locked(folder / f"{domain}.lock")
        if handle is None:
            continue
        try:
            yield domain
        finally:
            handle.close()  # closing the file releases its lock
        return
    raise ConfigurationError(
        f"every DDS domain {domains[0]}-{domains[-1]} is held by another run of the demo on this machine "
        f"(lock files in {folder}); wait for them to end"
    )


def _locked(path: Path) -> IO[str] | None:
    """``path`` opened and locked exclusively, or None when another claim holds it (or it cannot
    be opened: another user's file)."""
    try:
        handle = open(path, "a+")  # noqa: SIM115 - held open for the run, closed by the caller
    except OSError:
        return None
    with contextlib.suppress(OSError):
        os.chmod(path, 0o666)
    try:
        fcntl.flock(handle.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError as error:
        handle.close()
        if error.errno in (errno.EWOULDBLOCK, errno.EACCES):
            return None
        raise
    return handle
