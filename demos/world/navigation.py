"""Paths through the house: a visibility graph of waypoints and doorways, searched with Dijkstra.

Nodes are the waypoints and two points on either side of every doorway (so paths cross doors
square-on, with room for the robot's body). Two nodes are joined when the straight segment
between them keeps the robot's clearance from every wall and piece of furniture; edges weigh
their length. ``plan`` links the start and the goal to the nodes they can see, and takes the
shortest route (scipy.sparse.csgraph). A goal that no node can see (inside furniture, in a
corner closer to the walls than the robot's clearance) is reached by driving to the graph node
nearest to it and then straight on; ``reachable`` says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import shortest_path

from merlin2_sailor_demos.world.geometry import segment_rectangle_distance, segment_segment_distance
from merlin2_sailor_demos.world.house import House

#: Distance (m) of a doorway's two nodes from the wall, on either side.
DOOR_NODE_OFFSET = 0.5


@dataclass(frozen=True, slots=True)
class Plan:
    """Points to drive through, in order, ending at the goal; ``reachable`` is False when the last
    leg leaves the graph straight for a goal no node can see."""

    points: tuple[tuple[float, float], ...]
    reachable: bool
    nodes: tuple[str, ...] = ()

    @property
    def length(self) -> float:
        return sum(math.dist(a, b) for a, b in zip(self.points, self.points[1:], strict=False))


class NavigationGraph:
    def __init__(self, house: House, clearance: float, door_offset: float = DOOR_NODE_OFFSET) -> None:
        self.house = house
        self.clearance = clearance
        self._walls = [(np.array(w.start), np.array(w.end)) for w in house.walls]
        self._obstacles = [(piece.box.minimum[:2], piece.box.maximum[:2]) for piece in house.furniture]
        names, points = [], []
        for waypoint in house.waypoints:
            names.append(waypoint.name)
            points.append((waypoint.pose.x, waypoint.pose.y))
        for index, door in enumerate(house.doorways):
            for side, sign in (("a", -1.0), ("b", 1.0)):
                names.append(f"door_{index}_{side}")
                points.append(tuple(np.array([door.x, door.y]) + sign * door_offset * door.normal))
        self.names = tuple(names)
        self.points = np.array(points, dtype=np.float64).reshape(-1, 2)
        count = len(self.points)
        weights = np.zeros((count, count))
        for i in range(count):
            for j in range(i + 1, count):
                if self.segment_clear(self.points[i], self.points[j]):
                    weights[i, j] = weights[j, i] = max(float(np.linalg.norm(self.points[i] - self.points[j])), 1e-6)
        self.edges = tuple((self.names[i], self.names[j]) for i in range(count) for j in range(i + 1, count)
                           if weights[i, j] > 0)
        self._distances, self._predecessors = shortest_path(csr_matrix(weights), directed=False,
                                                            return_predecessors=True)

    def segment_clear(self, start: np.ndarray, end: np.ndarray) -> bool:
        """Whether a robot of the graph's clearance can drive straight from ``start`` to ``end``."""
        start, end = np.asarray(start, dtype=np.float64), np.asarray(end, dtype=np.float64)
        if any(segment_segment_distance(start, end, a, b) < self.clearance for a, b in self._walls):
            return False
        return all(segment_rectangle_distance(start, end, low, high) >= self.clearance
                   for low, high in self._obstacles)

    def plan(self, start: tuple[float, float], goal: tuple[float, float]) -> Plan:
        start_point, goal_point = np.asarray(start, dtype=np.float64), np.asarray(goal, dtype=np.float64)
        if self.segment_clear(start_point, goal_point):
            return Plan((tuple(goal_point),), True)
        start_links = self._visible_nodes(start_point)
        goal_links = self._visible_nodes(goal_point)
        reachable = bool(goal_links)
        if not start_links:
            start_links = [self._nearest_node(start_point)]
        if not goal_links:
            goal_links = [self._nearest_node(goal_point)]
        best, best_cost = None, math.inf
        for first in start_links:
            head = float(np.linalg.norm(self.points[first] - start_point))
            for last in goal_links:
                cost = head + self._distances[first, last] + float(np.linalg.norm(self.points[last] - goal_point))
                if cost < best_cost:
                    best, best_cost = (first, last), cost
        if best is None:
            return Plan((tuple(goal_point),), False)
        nodes = self._node_path(*best)
        points = [tuple(self.points[node]) for node in nodes] + [tuple(goal_point)]
        return Plan(tuple((float(x), float(y)) for x, y in points), reachable, tuple(self.names[n] for n in nodes))

    def _visible_nodes(self, point: np.ndarray) -> list[int]:
        return [index for index, node in enumerate(self.points) if self.segment_clear(point, node)]

    def _nearest_node(self, point: np.ndarray) -> int:
        return int(np.argmin(np.linalg.norm(self.points - point, axis=1)))

    def _node_path(self, first: int, last: int) -> list[int]:
        path = [last]
        while path[-1] != first:
            previous = int(self._predecessors[first, path[-1]])
            if previous < 0:
                return [first]
            path.append(previous)
        return path[::-1]
