"""Install merlin2_sailor as an ament_python package.

The ROS-free core lives in ``merlin2_sailor``; the state-machine behaviors and the demos live in
the top-level folders ``behaviors/`` and ``demos/`` of the repository and install as
``merlin2_sailor_behaviors`` and ``merlin2_sailor_demos``, so nothing claims the generic names
``behaviors`` or ``demos`` in a user's Python environment.
"""

from glob import glob

from setuptools import find_packages, setup

PACKAGE_NAME = "merlin2_sailor"

# Each ROS node, as "executable = module:function". The executable names are the ones that
# launch files and the README use.
NODE_ENTRY_POINTS = [
    "rgbd_player = merlin2_sailor_demos.rgbd_player_node:main",
    "topic_monitor = merlin2_sailor.ros.topic_monitor_node:main",
    "bag_recorder = merlin2_sailor.ros.bag_recorder_node:main",
    "knowledge_base = merlin2_sailor.ros.knowledge_base_node:main",
    "anchoring = merlin2_sailor.ros.anchoring_node:main",
    "detector = merlin2_sailor.ros.detector_node:main",
    "percept_generator = merlin2_sailor.ros.percept_node:main",
    "world = merlin2_sailor_demos.world_node:main",
    "behaviors = merlin2_sailor_behaviors.ros.behaviors_node:main",
    "mission = merlin2_sailor_behaviors.mission.mission_node:main",
    "mission_demo = merlin2_sailor_demos.mission_demo_node:main",
]

# Command-line tools.
TOOL_ENTRY_POINTS = [
    "sailor = merlin2_sailor.cli.main:main",
]



def _packages_under(folder: str, package: str) -> list[str]:
    """``package`` (installed from ``folder``) and every subpackage of it."""
    return [package] + [f"{package}.{name}" for name in find_packages(where=folder)]


setup(
    name=PACKAGE_NAME,
    version="0.1.0",
    packages=find_packages(include=[PACKAGE_NAME, f"{PACKAGE_NAME}.*"])
    + _packages_under("behaviors", "merlin2_sailor_behaviors")
    + _packages_under("demos", "merlin2_sailor_demos"),
    package_dir={
        "merlin2_sailor_behaviors": "behaviors",
        "merlin2_sailor_demos": "demos",
    },
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{PACKAGE_NAME}"]),
        (f"share/{PACKAGE_NAME}", ["package.xml"]),
        (f"share/{PACKAGE_NAME}/config", glob("config/*.*")),
        (f"share/{PACKAGE_NAME}/config/worlds", glob("config/worlds/*.yaml")),
        (f"share/{PACKAGE_NAME}/config/worlds/scenarios", glob("config/worlds/scenarios/*.yaml")),
        (f"share/{PACKAGE_NAME}/launch", glob("launch/*")),
    ],
    package_data={"merlin2_sailor": ["models/*.pt", "models/*.json"]},
    install_requires=["setuptools"],
    zip_safe=True,
    maintainer="merlin2_sailor developers",
    maintainer_email="dev@merlin2-sailor.local",
    description="SAILOR symbolic anchoring for ROS 2 Jazzy, as a MERLIN2 skill.",
    license="Apache-2.0",
    python_requires=">=3.10",
    entry_points={"console_scripts": NODE_ENTRY_POINTS + TOOL_ENTRY_POINTS},
)
