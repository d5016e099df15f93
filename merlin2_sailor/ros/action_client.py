"""An rclpy ActionClient whose requests cannot lose their responses to the executor.

rclpy's ActionClient (Jazzy's 7.1 series) sends a goal, cancel or result request first and only
then records the request's future under its sequence number. When the request is made from a
thread other than the executor's (every behaviour's worker thread does so), the executor can
take and handle the response in between: it finds no future for it, logs "Ignoring unexpected
result response. There may be more than one action server ..." and the future never completes
(ros2/rclpy#1123; fixed upstream after the release pinned here). That is how a demo mission
waited forever for the result of ``/behaviors/explore``.

:class:`RaceFreeActionClient` closes the window: sending a request and recording its future
happen under one lock, and the executor takes the same lock before it looks a response up. A
response can only exist once its request was sent, so by the time the executor holds the lock
the future is recorded. Only the three request paths and the response handler are touched; the
rest is rclpy's own client.
"""

from __future__ import annotations

import threading
from typing import Any

from rclpy.action import ActionClient

__all__ = ["RaceFreeActionClient"]


class RaceFreeActionClient(ActionClient):
    """An ActionClient safe to use from any thread while an executor spins its node."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self._request_lock = threading.Lock()
        super().__init__(*args, **kwargs)

    def send_goal_async(self, goal: Any, feedback_callback: Any = None, goal_uuid: Any = None) -> Any:
        with self._request_lock:
            return super().send_goal_async(goal, feedback_callback=feedback_callback, goal_uuid=goal_uuid)

    def _cancel_goal_async(self, goal_handle: Any) -> Any:
        with self._request_lock:
            return super()._cancel_goal_async(goal_handle)

    def _get_result_async(self, goal_handle: Any) -> Any:
        with self._request_lock:
            return super()._get_result_async(goal_handle)

    async def execute(self, taken_data: Any) -> None:
        # Wait out a request being sent on another thread: its future is recorded once the lock
        # is free. Not held while handling, so feedback callbacks may send requests themselves.
        with self._request_lock:
            pass
        await super().execute(taken_data)
