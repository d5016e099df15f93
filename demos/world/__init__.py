"""The simulated world of the demos: a house, its objects and a robot with an RGB-D camera.

ROS-free (NumPy, SciPy, OpenCV); the ``world`` node (:mod:`merlin2_sailor_demos.world_node`)
wraps it. Typical use::

    from merlin2_sailor_demos.world import World, load_world

    world = World(load_world("config/worlds/house.yaml"), seed=0)
    world.navigate_to(*world.house.waypoint("bedroom").pose.position)
    while world.navigation.state.value == "active":
        world.step(0.1)
    frame = world.render()              # colour, depth, camera poses
    detections = world.detect(frame)    # ground-truth detections, with configured noise
    truth = world.ground_truth()        # plain data for reports

One module per concept: ``house`` (rooms, doorways, walls, furniture, waypoints), ``objects``,
``textures`` / ``photos`` / ``materials``, ``navigation`` (graph and shortest paths), ``motion``
(path following), ``odometry``, ``camera``, ``depth_sensor``, ``rasteriser`` and ``renderer``,
``visibility``, ``ground_truth_detector``, ``scenario``, ``gripper``, ``world_file`` (loading),
``markers`` (what RViz should draw) and ``world`` (the whole).
"""

from merlin2_sailor_demos.world.geometry import Pose2D
from merlin2_sailor_demos.world.ground_truth_detector import DetectorNoise
from merlin2_sailor_demos.world.house import House
from merlin2_sailor_demos.world.world import NavigationState, SensorFrame, World
from merlin2_sailor_demos.world.world_file import WorldDescription, load_world

__all__ = ["DetectorNoise", "House", "NavigationState", "Pose2D", "SensorFrame", "World", "WorldDescription",
           "load_world"]
