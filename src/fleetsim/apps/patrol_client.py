"""``grobot_utilities/patrol_client``: send one endless patrol to the robot's patrol_server.

As the tutorial's script: ``args="<radius> <clockwise>"`` (``clockwise`` is true when it reads
``true`` in any case); 2 s of sim time after start it sends ``Patrol`` goal ``radius``,
``clockwise``, ``num_patrols = 0`` to the relative action ``patrol_server`` once the server is
up, and then waits for the result (for ever, as the server patrols for ever). Laps are logged
as the feedback reports them.
"""

from __future__ import annotations

import math

from fleetsim.errors import ParameterError
from fleetsim.msgs import grobot_utilities
from fleetsim.runtime import Node

START_DELAY = 2.0  # s of sim time, rospy.sleep(2)
POLL_PERIOD = 0.1  # s, how often it looks for the server once the delay is over


def patrol_goal_from_args(args: list[str], where: str):
    """The ``Patrol`` goal of patrol_client's command line; errors name the argument."""
    if len(args) < 2:
        raise ParameterError(
            f"{where}: args must be '<radius> <clockwise>' (e.g. args=\"1.5 true\"), got {args}"
        )
    try:
        radius = float(args[0])
    except ValueError:
        raise ParameterError(f"{where}: radius '{args[0]}' is not a number") from None
    if not (math.isfinite(radius) and radius > 0):
        raise ParameterError(f"{where}: radius must be a positive number of metres, got {radius}")
    return grobot_utilities.Patrol.Goal(
        radius=radius, clockwise=args[1].lower() == "true", num_patrols=0
    )


class PatrolClient(Node):
    """The patrol client; state: the goal, its handle once sent and the laps reported."""

    def __init__(self, runtime, name: str = "patrol_client", namespace: str = "/", **kw) -> None:
        super().__init__(runtime, name, namespace, **kw)
        self.goal = patrol_goal_from_args(self.args, f"{self.full_name} args")
        self.client = self.create_action_client(grobot_utilities.Patrol, "patrol_server")
        self.start = self.now() + START_DELAY
        self.handle = None
        self.completed_patrols = 0
        self._timer = self.create_timer(POLL_PERIOD, self._try_send)

    def _try_send(self) -> None:
        if self.handle is not None or self.now() < self.start - 1e-9:
            return
        if not self.client.wait_for_server():
            return
        self.handle = self.client.send_goal(
            self.goal, done_cb=self._on_done, feedback_cb=self._on_feedback
        )
        self._timer.cancel()

    def _on_feedback(self, handle, feedback) -> None:
        self.completed_patrols = int(feedback.completed_patrols)
        self.get_logger().info("completed patrols: %d", self.completed_patrols)

    def _on_done(self, handle) -> None:
        self.get_logger().info(
            "patrol ended with status %d%s",
            handle.status,
            f": {handle.text}" if handle.text else "",
        )
