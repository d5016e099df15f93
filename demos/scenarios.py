"""The scenario suite: the default house and the world files of ``config/worlds/scenarios/``.

A scenario is a world file with a ``mission`` section (:mod:`.world.mission`): the changes the
world makes, the mission the demo runs and its right outcome. Its name is the file's stem;
``default`` is the house of ``make demo`` itself. Adding a scenario is adding a file.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.resources import share_directory
from merlin2_sailor_demos.world.mission import MissionSpec
from merlin2_sailor_demos.world.world_file import WorldDescription, load_world

DEFAULT_SCENARIO = "default"
DEFAULT_WORLD = "worlds/house.yaml"
SCENARIO_FOLDER = "worlds/scenarios"


@dataclass(frozen=True)
class ScenarioEntry:
    """One scenario: its name, world file (a path under config/), what it shows, its mission."""

    name: str
    world_file: str
    description: str
    mission: MissionSpec

    @property
    def path(self) -> Path:
        return share_directory() / "config" / self.world_file


def _entry(name: str, world_file: str) -> ScenarioEntry:
    world: WorldDescription = load_world(share_directory() / "config" / world_file)
    return ScenarioEntry(name, world_file, world.description, world.mission or MissionSpec())


def scenario_names() -> list[str]:
    """``default`` first, then the scenario files' stems in alphabetical order."""
    folder = share_directory() / "config" / SCENARIO_FOLDER
    return [DEFAULT_SCENARIO, *sorted(path.stem for path in folder.glob("*.yaml"))]


def find_scenario(name: str) -> ScenarioEntry:
    """The scenario called ``name``, loaded and checked; a ConfigurationError lists the others."""
    if name == DEFAULT_SCENARIO:
        return _entry(name, DEFAULT_WORLD)
    names = scenario_names()
    if name not in names:
        raise ConfigurationError(f"no scenario '{name}'; scenarios: {', '.join(names)} "
                                 "(sailor demo --list-scenarios describes them)")
    return _entry(name, f"{SCENARIO_FOLDER}/{name}.yaml")


def all_scenarios() -> list[ScenarioEntry]:
    return [find_scenario(name) for name in scenario_names()]
