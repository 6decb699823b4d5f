"""The `Navigator`'s backend for a simulation in this process: an in-process ActionClient."""

from __future__ import annotations

from typing import Any

from fleetsim.errors import ActionError


class LocalBackend:
    """Talks to move_base through an in-process ActionClient on a node."""

    def __init__(self, node: Any, action: str, initialpose: str) -> None:
        from fleetsim.msgs import geometry_msgs, move_base_msgs

        self.node = node
        self.client = node.create_action_client(move_base_msgs.MoveBase, action)
        self.action = self.client.name
        self.initialpose = node.create_publisher(
            geometry_msgs.PoseWithCovarianceStamped, initialpose
        )
        self.handle: Any = None

    def now(self) -> float:
        return self.node.now()

    def send(self, goal_pose: Any, on_feedback, on_done) -> None:
        from fleetsim.msgs import move_base_msgs

        if not self.client.wait_for_server():
            raise ActionError(
                f"Navigator: no move_base action server at {self.action} (nothing publishes "
                f"{self.action}/status); start move_base in that namespace or fix the namespace"
            )
        self.handle = self.client.send_goal(
            move_base_msgs.MoveBaseGoal(target_pose=goal_pose),
            done_cb=lambda h: on_done(h.status, h.text),
            feedback_cb=lambda h, fb: on_feedback(fb),
        )

    def status(self) -> tuple[int, str]:
        h = self.handle
        return (h.status, h.text) if h is not None else (0, "")

    def cancel(self) -> None:
        if self.handle is not None and not self.handle.done:
            self.handle.cancel()

    def publish_initial_pose(self, msg: Any) -> None:
        self.initialpose.publish(msg)

    def spin(self, timeout: float | None, until) -> None:
        rt = self.node.runtime
        if until():
            return
        if timeout is None:
            rt.run(until=until)
        else:
            rt.run(duration=timeout, until=until)

    def close(self) -> None:
        """Nothing to release: the nodes live in the caller's runtime."""
