"""What the figures were measured on: CPU model, cores, memory, Python, OS, and how busy it was."""

from __future__ import annotations

import os
import platform
from typing import Any


def _read(path: str) -> str:
    try:
        with open(path) as file:
            return file.read()
    except OSError:
        return ""


def cpu_model() -> str:
    for line in _read("/proc/cpuinfo").splitlines():
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return platform.processor() or platform.machine() or "unknown"


def memory_gib() -> float | None:
    for line in _read("/proc/meminfo").splitlines():
        if line.startswith("MemTotal:"):
            return int(line.split()[1]) / 2**20
    return None


def load_average() -> tuple[float, float, float] | None:
    try:
        return os.getloadavg()
    except OSError:
        return None


def describe() -> dict[str, Any]:
    """The machine as a JSON-safe mapping (see :func:`summary` for one line of it)."""
    import numpy as np

    try:
        usable = len(os.sched_getaffinity(0))
    except AttributeError:
        usable = os.cpu_count()
    return {
        "cpu": cpu_model(),
        "architecture": platform.machine(),
        "logical_cpus": os.cpu_count(),
        "usable_cpus": usable,
        "memory_gib": memory_gib(),
        "python": f"{platform.python_implementation()} {platform.python_version()}",
        "numpy": np.__version__,
        "os": platform.platform(),
        "load_average": load_average(),
    }


def summary(machine: dict[str, Any] | None = None) -> str:
    machine = machine or describe()
    memory = f"{machine['memory_gib']:.0f} GiB RAM" if machine.get("memory_gib") else "RAM unknown"
    load = machine.get("load_average")
    busy = f", load average {load[0]:.2f}" if load else ""
    return (f"{machine['cpu']} ({machine['architecture']}), {machine['logical_cpus']} logical CPUs, {memory}, "
            f"{machine['python']}, {machine['os']}{busy}")
