"""Point the CMake files of the ROS 2 wheels at this virtual environment's headers.

The ros-jazzy-* wheels are built under /opt/python/cp311-cp311 and their exported CMake targets
name that builder's Python and NumPy include folders. Those do not exist on the machines that
install the wheels, so building any rosidl package against them fails until the paths are
rewritten. The rewrite is idempotent: files already pointing here are left untouched.
"""

from __future__ import annotations

import sys
import sysconfig
from pathlib import Path

import numpy

BUILDER_PREFIX = "/opt/python/cp311-cp311"
BUILDER_PYTHON_INCLUDE = f"{BUILDER_PREFIX}/include/python3.11"
BUILDER_NUMPY_INCLUDE = f"{BUILDER_PREFIX}/lib/python3.11/site-packages/numpy/_core/include"


def rewrite_cmake_paths(venv: Path) -> int:
    """Rewrite the builder's include paths in ``venv/share/*/cmake``; return the files changed."""
    replacements = {
        BUILDER_PYTHON_INCLUDE: sysconfig.get_paths()["include"],
        BUILDER_NUMPY_INCLUDE: numpy.get_include(),
    }
    changed = 0
    for cmake_file in sorted(venv.glob("share/*/cmake/*.cmake")):
        text = cmake_file.read_text()
        rewritten = text
        for old, new in replacements.items():
            rewritten = rewritten.replace(old, new)
        if rewritten != text:
            cmake_file.write_text(rewritten)
            changed += 1
    return changed


if __name__ == "__main__":
    venv_path = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(sys.prefix)
    print(f"[setup] pointed {rewrite_cmake_paths(venv_path)} ROS CMake files at this venv's headers")
