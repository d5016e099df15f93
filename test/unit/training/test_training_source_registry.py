"""The table of public training sources: names, forms, and what a ``--source`` value opens."""

from __future__ import annotations

import subprocess
import sys

import pytest

from merlin2_sailor.errors import ConfigurationError, DependencyError
from merlin2_sailor.training.external_source import ImageSource
from merlin2_sailor.training.source_registry import SOURCE_ENTRIES, SOURCE_FORMS, SOURCES, open_source


def test_every_entry_is_an_image_source_opened_from_a_specification() -> None:
    assert set(SOURCES.names) == set(SOURCE_ENTRIES) == {"nuscenes", "motfront"}
    for name, entry in SOURCE_ENTRIES.items():
        source_class = SOURCES.load(name)
        assert issubclass(source_class, ImageSource) and source_class.name == name
        assert "from_specification" in vars(source_class), name
        assert entry.form.startswith(f"{name}:") and entry.form in SOURCE_FORMS


@pytest.mark.parametrize("specification", ["kitti:/data", "nuscenes:", "motfront", ""])
def test_an_unknown_or_empty_specification_lists_the_forms(specification: str) -> None:
    with pytest.raises(ConfigurationError, match="use generated, nuscenes:DATAROOT.*or motfront:ROOT"):
        open_source(specification)


@pytest.mark.parametrize(
    ("specification", "dataroot"),
    [("nuscenes:/absent/nuscenes", "/absent/nuscenes"), ("nuscenes:/absent/nuscenes:v1.0-mini", "/absent/nuscenes")],
)
def test_a_nuscenes_version_is_the_last_part_without_a_slash(specification: str, dataroot: str) -> None:
    with pytest.raises(DependencyError, match=f"dataroot {dataroot} not found"):
        open_source(specification)


def test_the_table_imports_no_source() -> None:
    """The command line builds its help from the table, so reading it must cost nothing."""
    heavy = ("cv2", "numpy", "merlin2_sailor.training.nuscenes_source")
    probe = ("import sys, merlin2_sailor.training.source_registry as r; r.SOURCE_FORMS; "
             f"print(sorted(m for m in {heavy!r} if m in sys.modules))")
    completed = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=60, check=True)
    assert completed.stdout.strip() == "[]"
