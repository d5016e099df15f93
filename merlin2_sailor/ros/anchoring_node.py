"""anchoring: SAILOR's anchoring layer as a node: percepts in, anchors, events and facts out.

The anchoring layer itself is the ROS-free :class:`~merlin2_sailor.anchoring.service.AnchoringService`
(the core, the symbol counter and state file, the persistence worker, the matcher), built from the
parameters of :data:`~merlin2_sailor.anchoring.settings.SETTINGS` exactly as ``sailor replay``
builds it from the same parameter files. For every PerceptArray the core runs acquire / reacquire
(the matching table, then Hungarian) with the camera's pose, intrinsics and depth at the
percepts' stamp, so anchors that should have been visible but were not become missing. A timer
runs Track (expected effects, carried objects, forgetting). Off the hot path, the service's worker
thread syncs the anchors into the knowledge base by diff and saves them to disk, so they survive
a restart with the same symbols. Messages are built from frozen views of the anchors.

Topics: in ``percepts``, ``color/camera_info``, ``camera_pose``, ``depth/image_raw`` (optional,
for occlusion), ``robot_pose`` (for carried objects); out ``anchors`` (latched, on change),
``anchor_events``, ``anchor_markers``. Services (private): ``~/get_anchors``, ``~/find_anchor``,
``~/forget_anchor``, ``~/expect_anchor``.
"""

from __future__ import annotations

import threading
from collections import Counter
from collections.abc import Sequence
from typing import Any

import numpy as np
from geometry_msgs.msg import PoseStamped
from rclpy.node import Node
from sensor_msgs.msg import CameraInfo, Image
from std_msgs.msg import Header
from visualization_msgs.msg import MarkerArray

from merlin2_sailor.anchoring.anchor import AnchorState
from merlin2_sailor.anchoring.anchor_view import AnchorView
from merlin2_sailor.anchoring.anchoring import AnchoringResult, conclusion_refusal
from merlin2_sailor.anchoring.events import AnchorEventKind
from merlin2_sailor.anchoring.expectation import Expectation
from merlin2_sailor.anchoring.service import AnchoringService
from merlin2_sailor.anchoring.settings import SETTINGS, AnchoringSettings, settings_from_parameters
from merlin2_sailor.anchoring.visibility import CameraView
from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import ConfigurationError, InvalidInputError, SailorError
from merlin2_sailor.perception.stamped_buffer import StampedBuffer
from merlin2_sailor.ros.conversions import (
    camera_info_to_intrinsics,
    depth_to_metres,
    image_to_array,
    percepts_from_message,
    pose_from_message,
    stamp_to_seconds,
)
from merlin2_sailor.ros.conversions.anchoring import anchor_markers, anchors_to_message, events_to_message
from merlin2_sailor.ros.newest_frame_mailbox import NewestFrameMailbox
from merlin2_sailor.ros.node_runner import run_node
from merlin2_sailor.ros.parameters import declare_parameter
from merlin2_sailor.ros.qos import EVENTS, LATCHED, SENSOR_DATA
from merlin2_sailor.ros.stores import open_store
from merlin2_sailor.ros.tf_poses import TfCameraPoses
from merlin2_sailor_interfaces import srv
from merlin2_sailor_interfaces.msg import AnchorArray, AnchorEventArray, PerceptArray

NODE_NAME = "anchoring"
#: Percepts stamped further than this ahead of the node's clock are refused: a camera clock gone
#: wrong would otherwise expire every missing anchor at once ("missing since decades").
FUTURE_STAMP_LIMIT_SECONDS = 10.0
#: How often the percept arrays dropped while busy are reported (when there were any).
DROP_REPORT_PERIOD_SECONDS = 5.0


def declare_settings(node: Node) -> AnchoringSettings:
    """Declare every anchoring parameter of :data:`~merlin2_sailor.anchoring.settings.SETTINGS` with
    its descriptor, and build the settings from their values as ``sailor replay`` builds them from
    the same files (:func:`~merlin2_sailor.anchoring.settings.settings_from_parameters`)."""
    values = {
        row.name: declare_parameter(
            node, row.name, row.default,
            row.description + (f" One of: {', '.join(row.choices)}." if row.choices else ""),
            minimum=row.minimum, maximum=row.maximum)
        for row in SETTINGS
    }
    source = f"the parameters of node {node.get_fully_qualified_name()}"
    return settings_from_parameters(values, dict.fromkeys(values, source))


class AnchoringNode(Node):
    def __init__(self, **node_options: Any) -> None:
        super().__init__(NODE_NAME, **node_options)
        settings = declare_settings(self)
        self.service = AnchoringService(settings, log=self._log, open_knowledge_base=open_store)
        # The core is single-threaded: the frame thread, the executor's callbacks and the
        # persistence worker take this lock around it, and read anchors as views taken under it.
        self._lock = self.service.lock
        self._anchoring = self.service.anchoring
        if self.service.restored:
            self.get_logger().info(
                f"restored {self.service.restored} anchors from {settings.persistence.state_folder}")
        self._world_frame = settings.core.world_frame
        self._intrinsics: CameraIntrinsics | None = None
        tolerance = settings.timing.stamp_tolerance
        self._poses: StampedBuffer[Pose] = StampedBuffer(tolerance=tolerance)
        # A depth image for each frame waiting, and for the one being anchored.
        self._depths: StampedBuffer[np.ndarray] = StampedBuffer(capacity=settings.timing.frame_backlog + 2,
                                                                tolerance=tolerance)
        self._robot_pose: Pose | None = None

        self._anchors_publisher = self.create_publisher(AnchorArray, "anchors", LATCHED)
        self._events_publisher = self.create_publisher(AnchorEventArray, "anchor_events", EVENTS)
        self._markers_publisher = self.create_publisher(MarkerArray, "anchor_markers", LATCHED)
        self.create_subscription(PerceptArray, "percepts", self._on_percepts, SENSOR_DATA)
        self.create_subscription(CameraInfo, "color/camera_info", self._on_camera_info, SENSOR_DATA)
        self._tf_poses: TfCameraPoses | None = None
        self._camera_frame = ""
        if settings.inputs.pose_source == "tf":
            self._tf_poses = TfCameraPoses(self, self._world_frame, alternative="pose_source 'topic', camera_pose")
        else:
            self.create_subscription(PoseStamped, "camera_pose", self._on_camera_pose, SENSOR_DATA)
        self.create_subscription(Image, "depth/image_raw", self._on_depth, SENSOR_DATA)
        self.create_subscription(PoseStamped, "robot_pose", self._on_robot_pose, SENSOR_DATA)
        self.create_service(srv.GetAnchors, "~/get_anchors", self._get_anchors)
        self.create_service(srv.FindAnchor, "~/find_anchor", self._find_anchor)
        self.create_service(srv.ForgetAnchor, "~/forget_anchor", self._forget_anchor)
        self.create_service(srv.ExpectAnchor, "~/expect_anchor", self._expect_anchor)
        self.create_timer(settings.timing.track_period, self._track)
        # Percept arrays go to a worker through a mailbox of a few frames: a burst of work is caught
        # up on; when anchoring falls further behind the camera, the oldest waiting frames are let
        # go, counted and reported.
        self._mailbox = NewestFrameMailbox(settings.timing.frame_backlog)
        self._anchoring_thread = threading.Thread(target=self._anchor_frames, name="anchoring", daemon=True)
        self._anchoring_thread.start()
        self._reported_drops = 0
        self._reported_embedding = (0, 0)
        self._unresolved: Counter[str] = Counter()  # anchor -> views not yet told from it, this period
        self._offsets: list[float] = []  # pose errors (m) taken out of frames this period
        self._held_frames = 0  # frames this period whose views of a row were held out (read two ways)
        self.create_timer(DROP_REPORT_PERIOD_SECONDS, self._report)

        self.service.start()
        self._publish_state()
        knowledge_base = settings.persistence.knowledge_base
        inference = self.service.describe_inference()
        self.get_logger().info(
            f"anchoring in '{self._world_frame}' with the {settings.matcher.name} matcher"
            f"{f' on {inference}' if inference else ''}; knowledge base: {knowledge_base or 'none'}")

    def destroy_node(self) -> None:
        self._mailbox.close()
        self._anchoring_thread.join(timeout=5.0)
        self.service.close()
        super().destroy_node()

    def _log(self, level: str, message: str) -> None:
        # One call site per severity: rclpy raises ValueError when one line logs at two severities,
        # which after a knowledge-base outage failed every persistence step (nothing saved again).
        logger = self.get_logger()
        if level == "error":
            logger.error(message)
        elif level == "warning":
            logger.warning(message)
        else:
            logger.info(message)

    # Inputs.

    def _on_camera_info(self, message: CameraInfo) -> None:
        try:
            self._intrinsics = camera_info_to_intrinsics(message)
            self._camera_frame = message.header.frame_id  # the optical frame, for TF
        except SailorError as error:
            self.get_logger().warning(f"dropped camera info: {error}", throttle_duration_sec=5.0)

    def _on_camera_pose(self, message: PoseStamped) -> None:
        try:
            self._poses.add(stamp_to_seconds(message.header.stamp), pose_from_message(message.pose))
        except SailorError as error:
            self.get_logger().warning(f"dropped camera pose: {error}", throttle_duration_sec=5.0)

    def _on_robot_pose(self, message: PoseStamped) -> None:
        try:
            self._robot_pose = pose_from_message(message.pose)
        except SailorError as error:
            self.get_logger().warning(f"dropped robot pose: {error}", throttle_duration_sec=5.0)

    def _on_depth(self, message: Image) -> None:
        try:
            depth = depth_to_metres(image_to_array(message), message.encoding)
        except SailorError as error:
            self.get_logger().warning(f"dropped depth image: {error}", throttle_duration_sec=5.0)
            return
        self._depths.add(stamp_to_seconds(message.header.stamp), depth)

    def _on_percepts(self, message: PerceptArray) -> None:
        self._mailbox.put(message)

    def _anchor_frames(self) -> None:
        while (message := self._mailbox.take()) is not None:
            try:
                self._anchor_frame(message)
            except Exception as error:  # noqa: BLE001 - one frame must not stop anchoring
                self.get_logger().error(f"frame dropped: anchoring failed: {error!r}")

    def _report(self) -> None:
        self._report_drops()
        self._report_embedding()
        self._report_unresolved()
        self._report_offsets()

    def _report_unresolved(self) -> None:
        """Views left unresolved in the last period: too far to tell from an anchor (far_view), or a
        first view of another colour where it stood (colour_evidence)."""
        if not self._unresolved:
            return
        counts, self._unresolved = self._unresolved, Counter()
        anchors = ", ".join(f"{symbol} ({views})" for symbol, views in sorted(counts.items()))
        self.get_logger().info(f"views in the last {DROP_REPORT_PERIOD_SECONDS:g} s that could not yet be told from "
                               f"{anchors} (too far to tell, or a first view of another colour): left unresolved "
                               "until a closer or a second view")

    def _report_offsets(self) -> None:
        """Frames seen off their anchors by a shared pose error in the last period
        (frame_registration): taken out, or, where it could be read two ways, their views of the
        row held out. Many, or large ones, say the robot's localisation drifts."""
        offsets, self._offsets = self._offsets, []
        held, self._held_frames = self._held_frames, 0
        if offsets:
            self.get_logger().info(
                f"{len(offsets)} frame(s) in the last {DROP_REPORT_PERIOD_SECONDS:g} s were seen off their anchors by "
                f"one shared pose error (up to {max(offsets):.2f} m), taken out before matching")
        if held:
            self.get_logger().info(
                f"{held} frame(s) in the last {DROP_REPORT_PERIOD_SECONDS:g} s were seen off their anchors by a pose "
                "error that could be read two ways (a row of look-alikes): their views of the row were held out")

    def _report_embedding(self) -> None:
        """How many crops the last period embedded, and how many took a recent crop's embedding."""
        embedder = self.service.embedder
        counts = (getattr(embedder, "embedded", None), getattr(embedder, "reused", None))
        if counts[0] is None or counts[1] is None or counts == self._reported_embedding:
            return
        embedded, reused = counts[0] - self._reported_embedding[0], counts[1] - self._reported_embedding[1]
        self._reported_embedding = counts
        self.get_logger().info(f"crops in the last {DROP_REPORT_PERIOD_SECONDS:g} s: {embedded} embedded, {reused} "
                               "took the embedding of the same view a moment before")

    def _report_drops(self) -> None:
        dropped = self._mailbox.dropped
        if dropped > self._reported_drops:
            self.get_logger().warning(
                f"{dropped - self._reported_drops} percept arrays dropped in the last "
                f"{DROP_REPORT_PERIOD_SECONDS:g} s while busy ({self._mailbox.capacity} kept waiting, the oldest "
                f"let go; {dropped} since start)")
            self._reported_drops = dropped

    def _anchor_frame(self, message: PerceptArray) -> None:
        stamp = stamp_to_seconds(message.header.stamp)
        try:
            self._refuse_future_stamps(stamp, message)
            percepts = percepts_from_message(message)
            with self._lock:
                result = self._anchoring.process(percepts, self._camera_view(stamp, message.header.stamp), stamp)
        except SailorError as error:
            self.get_logger().warning(f"dropped {len(message.percepts)} percepts: {error}",
                                      throttle_duration_sec=5.0)
            return
        self._unresolved.update(result.unresolved)
        if result.frame_offset is not None and result.frame_offset.off_anchors:
            self._offsets.append(result.frame_offset.distance)
        self._held_frames += bool(result.held)
        self._publish(result)

    def _refuse_future_stamps(self, stamp: float, message: PerceptArray) -> None:
        latest = max([stamp, *(stamp_to_seconds(percept.stamp) for percept in message.percepts)])
        lead = latest - self.get_clock().now().nanoseconds * 1e-9
        if lead > FUTURE_STAMP_LIMIT_SECONDS:
            raise InvalidInputError(
                f"stamped {lead:.0f} s ahead of this node's clock (more than {FUTURE_STAMP_LIMIT_SECONDS:g} s); "
                "synchronise the clocks of the camera and this computer")

    def _camera_view(self, stamp: float, stamp_message: Any) -> CameraView | None:
        """The camera as it was at ``stamp``; without it no anchor is judged missing.

        Raises:
            InvalidInputError: with TF, no transform for the camera at that stamp (the frame is dropped).
        """
        if self._tf_poses is not None:
            if self._intrinsics is None:
                return None
            pose = self._tf_poses.lookup(self._camera_frame, stamp_message)
        else:
            pose = self._poses.nearest(stamp)
        if self._intrinsics is None or pose is None:
            return None
        depth = self._depths.nearest(stamp)
        if depth is not None and depth.shape != (self._intrinsics.height, self._intrinsics.width):
            depth = None
        return CameraView(self._intrinsics, pose, depth)

    def _track(self) -> None:
        now = self.get_clock().now().nanoseconds * 1e-9
        with self._lock:
            result = self._anchoring.track(now, self._robot_pose)
        self._publish(result)

    # Outputs: messages are built from views taken under the lock, never from live anchors,
    # which the frame thread may be changing meanwhile.

    def _publish(self, result: AnchoringResult) -> None:
        if not result.events:
            return
        # The anchors the events name, looked up one by one: walking every anchor per frame
        # would cost as much as the frame itself with thousands of anchors.
        named = self.service.views_of(event.symbol for event in result.events)
        with self._lock:  # forgotten anchors have left the core; copied under the lock all the same
            named.update({anchor.symbol: AnchorView.of(anchor) for anchor in result.forgotten})
        class_names = {symbol: view.class_name for symbol, view in named.items()}
        tentative = {symbol for symbol, view in named.items() if view.state is AnchorState.TENTATIVE}
        header = Header(stamp=self.get_clock().now().to_msg(), frame_id=self._world_frame)
        self._events_publisher.publish(events_to_message(result.events, class_names, header))
        for event in result.events:  # a running account; reacquisitions would flood it, but not those of
            # missing anchors: each may be a wrong identity in the making, and says why it took the view
            if event.kind is not AnchorEventKind.REACQUIRED or event.details.get("was_missing"):
                # Tentative said out loud: a false detection makes one, and it goes unconfirmed.
                status = " [tentative]" if (event.kind is AnchorEventKind.ACQUIRED
                                            and event.symbol in tentative) else ""
                details = ", ".join(f"{key}={value}" for key, value in event.details.items())
                self.get_logger().info(
                    f"{event.kind.value} {event.symbol} ({class_names.get(event.symbol, '?')}){status}"
                    + (f": {details}" if details else ""))
        self._publish_state()

    def _publish_state(self) -> None:
        views = self.service.views()
        header = Header(stamp=self.get_clock().now().to_msg(), frame_id=self._world_frame)
        self._anchors_publisher.publish(anchors_to_message(views, header))
        self._markers_publisher.publish(anchor_markers(views, header))

    # Services.

    def _get_anchors(self, request: srv.GetAnchors.Request, response: srv.GetAnchors.Response) -> Any:
        views = self.service.views(lambda anchor: (not request.symbol or anchor.symbol == request.symbol)
                                   and (not request.class_name or anchor.class_name == request.class_name))
        response.anchors = anchors_to_message(views, Header()).anchors
        response.frame_id = self._world_frame
        return response

    def _find_anchor(self, request: srv.FindAnchor.Request, response: srv.FindAnchor.Response) -> Any:
        if not request.symbol and not request.class_name:
            response.message = "give a symbol or a class name"
            return response
        near = (np.array([request.point.x, request.point.y, request.point.z])
                if request.use_point else None)
        try:
            with self._lock:
                anchor = self._anchoring.find(
                    symbol=request.symbol or None, class_name=request.class_name or None, near=near)
                found = AnchorView.of(anchor) if anchor is not None else None
        except SailorError as error:  # a point that is not 3 finite numbers: refused, not a crash
            response.message = str(error)
            return response
        response.found = found is not None
        if found is None:
            response.message = f"no anchor for {request.symbol or request.class_name!r}"
        else:
            response.anchor = anchors_to_message([found], Header()).anchors[0]
        return response

    def _forget_anchor(self, request: srv.ForgetAnchor.Request, response: srv.ForgetAnchor.Response) -> Any:
        now = self.get_clock().now().nanoseconds * 1e-9
        try:
            with self._lock:
                event = self._anchoring.forget(request.symbol, now)
        except SailorError as error:
            response.message = str(error)
            return response
        self._publish(AnchoringResult(stamp=now, events=(event,)))
        response.success = True
        return response

    def _expect_anchor(self, request: srv.ExpectAnchor.Request, response: srv.ExpectAnchor.Response) -> Any:
        now = self.get_clock().now().nanoseconds * 1e-9
        position = np.array([request.position.x, request.position.y, request.position.z])
        result, refusal = None, ""
        try:
            with self._lock:
                if request.symbol not in self._anchoring:
                    raise ConfigurationError(f"no anchor '{request.symbol}'")
                if request.expectation == request.EXPECT_AT:
                    result = self._anchoring.expect(request.symbol, Expectation.at(
                        position, now, place=request.place, source=request.source, radius=float(request.radius)))
                elif request.expectation == request.EXPECT_CARRIED:
                    self._anchoring.expect(request.symbol, Expectation.carried(
                        now, offset=position, source=request.source), robot_pose=self._robot_pose)
                elif request.expectation == request.CLEAR:
                    self._anchoring.clear_expectation(request.symbol)
                elif request.expectation == request.CONCLUDE_SEARCH:
                    result = self._anchoring.conclude_search(request.symbol)
                    refusal = conclusion_refusal(self._anchoring.get(request.symbol), result)
                else:
                    raise ConfigurationError(f"unknown expectation {request.expectation}")
        except SailorError as error:
            response.message = str(error)
            return response
        response.success = not refusal
        response.message = refusal
        if refusal:
            self.get_logger().info(f"a search for {request.symbol} concluded taking nothing: {refusal}")
        if result is not None and result.events:
            self._publish(result)  # a search that found its object under a newer anchor: the merge
        else:
            self._publish_state()
        return response


def main(argv: Sequence[str] | None = None) -> int:
    return run_node(AnchoringNode, argv)


if __name__ == "__main__":
    raise SystemExit(main())
