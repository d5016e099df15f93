"""The code passes the project's lint (ruff.toml): unused imports, import order, bugbear, ..."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

REPOSITORY_ROOT = Path(__file__).resolve().parent.parent


def test_ruff_finds_nothing() -> None:
    completed = subprocess.run(
        [sys.executable, "-m", "ruff", "check", "--no-cache", str(REPOSITORY_ROOT)],
        capture_output=True, text=True, timeout=120, cwd=REPOSITORY_ROOT,
    )
    assert completed.returncode == 0, completed.stdout + completed.stderr
