"""The anchoring node's services (``get_anchors``, ``find_anchor``, ``expect_anchor``) as an
:class:`~merlin2_sailor_behaviors.actions.clients.AnchoringPort`."""

from __future__ import annotations

from typing import Any

from merlin2_sailor_behaviors.actions.clients import AnchorReport, Point, finite_point
from merlin2_sailor_behaviors.actions.errors import BehaviorError
from merlin2_sailor_behaviors.ros.conversions import anchor_report, point_message
from merlin2_sailor_behaviors.ros.service_caller import ServiceCaller
from merlin2_sailor_interfaces import srv


class RosAnchoringClient:
    """Calls the services of the anchoring node named ``anchoring_node`` (e.g. ``/anchoring``)."""

    def __init__(self, caller: ServiceCaller, anchoring_node: str = "/anchoring") -> None:
        self._caller = caller
        self._node_name = anchoring_node.rstrip("/") or "/anchoring"
        self._provider = f"the anchoring node {self._node_name}"

    def _call(self, service_type: type, service: str, request: Any) -> Any:
        return self._caller.call(service_type, f"{self._node_name}/{service}", request, self._provider)

    def get_anchor(self, symbol: str) -> AnchorReport | None:
        response = self._call(srv.GetAnchors, "get_anchors", srv.GetAnchors.Request(symbol=symbol))
        matches = [anchor_report(a) for a in response.anchors if a.symbol == symbol]
        return matches[0] if matches else None

    def get_anchors(self, class_name: str = "") -> tuple[AnchorReport, ...]:
        response = self._call(srv.GetAnchors, "get_anchors", srv.GetAnchors.Request(class_name=class_name))
        return tuple(anchor_report(a) for a in response.anchors)

    def find_anchor(
        self, symbol: str = "", class_name: str = "", near: Point | None = None
    ) -> AnchorReport | None:
        request = srv.FindAnchor.Request(symbol=symbol, class_name=class_name)
        if near is not None:
            request.use_point = True
            request.point = point_message(finite_point(near, "a point to find near"))
        response = self._call(srv.FindAnchor, "find_anchor", request)
        return anchor_report(response.anchor) if response.found else None

    def expect_at(self, symbol: str, position: Point, place: str, source: str, radius: float = 0.0) -> None:
        self._expect(srv.ExpectAnchor.Request.EXPECT_AT, symbol, position, place, source, radius)

    def expect_carried(self, symbol: str, offset: Point, source: str) -> None:
        self._expect(srv.ExpectAnchor.Request.EXPECT_CARRIED, symbol, offset, "", source)

    def clear_expectation(self, symbol: str, source: str) -> None:
        self._expect(srv.ExpectAnchor.Request.CLEAR, symbol, (0.0, 0.0, 0.0), "", source)

    def conclude_search(self, symbol: str, source: str) -> bool:
        request = srv.ExpectAnchor.Request(symbol=symbol, expectation=srv.ExpectAnchor.Request.CONCLUDE_SEARCH,
                                           source=source)
        return bool(self._call(srv.ExpectAnchor, "expect_anchor", request).success)

    def _expect(
        self, expectation: int, symbol: str, position: Point, place: str, source: str, radius: float = 0.0
    ) -> None:
        request = srv.ExpectAnchor.Request(
            symbol=symbol,
            expectation=expectation,
            position=point_message(finite_point(position, f"the expected position of {symbol}")),
            place=place,
            source=source,
            radius=float(radius),
        )
        response = self._call(srv.ExpectAnchor, "expect_anchor", request)
        if not response.success:
            raise BehaviorError(f"the anchoring layer refused the expectation on {symbol}: {response.message}")
