"""Progress bars for the long steps (embedding, epochs), quiet when output is not a terminal.

tqdm draws them when installed; without it, or when ``SAILOR_PROGRESS=0``, a silent stand-in
with the same ``update`` / ``set_postfix`` verbs is used, so callers never branch.
"""

from __future__ import annotations

import os
import sys
from typing import Any


class _Silent:
    def __enter__(self) -> _Silent:
        return self

    def __exit__(self, *exception: object) -> None:
        return None

    def update(self, count: int = 1) -> None:
        return None

    def set_postfix(self, *arguments: Any, **values: Any) -> None:
        return None


def progress_bar(total: int | None, description: str, unit: str = "it") -> Any:
    """A tqdm bar on stderr when it is a terminal (or ``SAILOR_PROGRESS=1``), else a silent one."""
    wanted = os.environ.get("SAILOR_PROGRESS")
    if wanted == "0" or (wanted != "1" and not sys.stderr.isatty()):
        return _Silent()
    try:
        from tqdm import tqdm
    except ImportError:
        return _Silent()
    return tqdm(total=total, desc=description, unit=unit, dynamic_ncols=True, leave=False)
