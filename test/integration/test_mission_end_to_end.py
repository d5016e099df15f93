"""End to end over DDS: a mission plans over anchored facts, perception contradicts one, and the
mission replans and succeeds.

Every part is a separate process talking over DDS on loopback, as on a robot: the simulated
world (camera, ground-truth detector, navigation, odometry), the percept generator, the anchoring
node, the knowledge base, the behaviours' action servers and two mission nodes. The story:

1. explore the kitchen and go to the hall: the red mug is anchored, ``object_at(<mug>, kitchen)``;
2. behind the robot's back the world moves the mug to the bedroom;
3. mission ``robot_near(<mug>)``: the plan relies on the mug being in the kitchen (navigation,
   then approach_object). On arrival the navigation tells the anchoring layer what it expects
   there, the camera sees the place empty, Track marks the mug missing and the fact is
   retracted; the dispatcher replans: find_object searches, reacquires the mug in the bedroom
   under the same symbol, and the mission succeeds with the knowledge base telling the truth.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from merlin2_sailor.knowledge import open_store

WORLDS = Path(__file__).resolve().parent / "worlds"
WORLD_FILE = WORLDS / "small_house.yaml"
GROUNDING_FILE = WORLDS / "small_house_grounding.yaml"
MISSION_TIMEOUT = 180.0


def run_mission(node_process, log: Path, *arguments: str) -> tuple[int, str]:
    """Run a mission node to its end (draining its output so it never blocks on a full pipe);
    its running account is also kept in ``log``, for whoever has to read a failure."""
    mission = node_process("mission", "--ros-args", *arguments)
    try:
        out, _ = mission.process.communicate(timeout=MISSION_TIMEOUT)
    except Exception:
        mission.stop()
        raise
    mission.output.append(out or "")
    log.write_text(mission.text)
    return mission.process.returncode, mission.text


def ground_truth(folder: Path) -> dict:
    return json.loads((folder / "ground_truth.json").read_text())


def true_position(folder: Path, object_id: str) -> list[float]:
    return next(obj["position"] for obj in ground_truth(folder)["objects"] if obj["id"] == object_id)


def facts(store_path: Path, predicate: str) -> set[tuple[str, ...]]:
    with open_store(f"sqlite://{store_path}") as store:
        return {p.objects for p in store.propositions.get_all() if p.predicate == predicate and not p.is_goal}


@pytest.mark.ros
@pytest.mark.timeout(600)
def test_a_mission_replans_when_perception_retracts_the_fact_it_relied_on(tmp_path, node_process, ros_probe):
    data = tmp_path / "run"
    data.mkdir()
    knowledge = data / "knowledge.db"
    grounding = f"grounding:={GROUNDING_FILE}"
    graph = {
        "knowledge_base": node_process(
            "knowledge_base", "--ros-args", "-r", "__ns:=/merlin2", "-p", f"store:=sqlite://{knowledge}"),
        "world": node_process(
            "world", "--ros-args", "-p", f"world_file:={WORLD_FILE}", "-p", f"report_folder:={data}",
            "-p", "rate_hz:=10.0", "-p", "log_period:=0.0"),
        "percept_generator": node_process(
            "percept_generator", "--ros-args", "-r", "__ns:=/camera", "-p", "report_period:=60.0",
            "-p", "maximum_depth:=4.5"),
        "anchoring": node_process(
            "anchoring", "--ros-args", "-p", f"state_folder:={data / 'anchoring'}", "-p", grounding,
            "-p", "knowledge_base:=ros:///merlin2", "-p", "sync_period:=0.2",
            "-r", "percepts:=/camera/percepts", "-r", "color/camera_info:=/camera/color/camera_info",
            "-r", "camera_pose:=/camera/camera_pose", "-r", "depth/image_raw:=/camera/depth/image_raw"),
        "behaviors": node_process("behaviors", "--ros-args", "-p", grounding, "-p", "look_dwell:=0.3"),
    }
    try:
        run_story(data, knowledge, node_process, ros_probe)
        for name, process in graph.items():
            assert process.stop() == 0, f"{name}:\n{process.text[-3000:]}"
    finally:  # every node's output, for whoever has to read a failure
        for name, process in graph.items():
            process.stop()
            (data / f"{name}.log").write_text(process.text)


def run_story(data: Path, knowledge: Path, node_process, ros_probe) -> None:
    for name in ("/merlin2/knowledge_base", "/world", "/camera/percept_generator", "/anchoring", "/behaviors"):
        assert ros_probe.wait_for_node(name, timeout=60.0), f"{name} did not start"

    # 1. Explore the kitchen, then leave it.
    code, account = run_mission(
        node_process, data / "explore.log", "-p", "goals:=['explored(kitchen)', 'robot_at(hall)']",
        "-p", "actions:=['navigation', 'explore']", "-p", "mission_name:=explore")
    assert code == 0, account
    cups_in_kitchen = [objects for objects in facts(knowledge, "object_at") if objects[1] == "kitchen"]
    assert len(cups_in_kitchen) == 1, (facts(knowledge, "object_at"), account)
    mug = cups_in_kitchen[0][0]
    assert mug.startswith("cup_")

    # 2. The world moves the mug while the robot is in the hall.
    assert ros_probe.wait_for(lambda: true_position(data, "red_mug")[0] > 5.5, timeout=30.0), ground_truth(data)

    # 3. Go to the mug: the plan relies on object_at(mug, kitchen), which perception retracts.
    code, account = run_mission(
        node_process, data / "fetch.log", "-p", f"goals:=['robot_near({mug})']",
        "-p", "actions:=['navigation', 'approach_object', 'find_object']", "-p", "mission_name:=fetch")
    assert code == 0, account
    assert f"approach_object({mug}, kitchen)" in account  # the first plan trusted the old fact
    assert "replanning" in account
    # Aries returns the first plan it finds, not the shortest: the replan may start the search at
    # another waypoint (driving there first) rather than where the robot stands. Or no search is
    # needed: driving there, the camera may watch the bedroom before the mug appears in it, and the
    # anchoring layer then takes the mug seen there for the lost one (a relocation), so the next
    # plan approaches it where it now is (CI, 4 December).
    found_by_search = re.search(rf"find_object\({mug}, \w+\) succeeded", account)
    found_on_the_way = f"forgotten: moved: it appeared where the camera had watched: it is {mug}" in account
    assert found_by_search or found_on_the_way, account
    assert f"- object_at({mug}, kitchen)" in account  # the retraction, as it happened
    # The knowledge base tells the truth, under the same symbol: no second cup was anchored.
    assert facts(knowledge, "object_at") >= {(mug, "bedroom")}
    assert (mug, "kitchen") not in facts(knowledge, "object_at")
    assert facts(knowledge, "missing") == set()
    assert facts(knowledge, "robot_near") == {(mug,)}
    with open_store(f"sqlite://{knowledge}") as store:
        cups = sorted(o.name for o in store.objects.get_all() if o.type == "cup")
    assert cups == [mug]
