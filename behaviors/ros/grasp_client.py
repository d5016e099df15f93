"""The Grasp service (the simulated world's gripper) as a
:class:`~merlin2_sailor_behaviors.actions.clients.GraspPort`."""

from __future__ import annotations

from merlin2_sailor_behaviors.actions.clients import GraspResult, Point, finite_point
from merlin2_sailor_behaviors.ros.conversions import point_message
from merlin2_sailor_behaviors.ros.service_caller import ServiceCaller
from merlin2_sailor_interfaces import srv


class RosGraspClient:
    """Calls a Grasp service (default ``/world/grasp``)."""

    def __init__(self, caller: ServiceCaller, service: str = "/world/grasp") -> None:
        self._caller = caller
        self._service = service

    def pick(self, class_name: str, target: Point) -> GraspResult:
        request = srv.Grasp.Request(operation=srv.Grasp.Request.PICK, class_name=class_name,
                                    target=point_message(finite_point(target, "a pick target")))
        return self._grasp(request)

    def place(self, target: Point) -> GraspResult:
        request = srv.Grasp.Request(operation=srv.Grasp.Request.PLACE,
                                    target=point_message(finite_point(target, "a place target")))
        return self._grasp(request)

    def _grasp(self, request: srv.Grasp.Request) -> GraspResult:
        response = self._caller.call(srv.Grasp, self._service, request, "the gripper (or the simulated world)")
        return GraspResult(bool(response.success), response.message)
