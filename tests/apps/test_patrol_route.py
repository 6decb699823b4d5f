"""patrol_route's waypoints: bad input is named; the route is driven in order with its stops."""

from __future__ import annotations

import pytest

from fleetsim.apps.patrol_route import PatrolRoute, waypoints_from_param
from fleetsim.errors import ParameterError
from fleetsim.msgs import move_base_msgs
from fleetsim.runtime import Node, Runtime


def test_waypoints_are_read_as_x_y_yaw_stop():
    assert waypoints_from_param([[1, 2, 0.5, 3]], "w") == [(1.0, 2.0, 0.5, 3.0)]


@pytest.mark.parametrize(
    ("raw", "match"),
    [
        ([], "'waypoints' is empty"),
        ([[1.0, 2.0, 0.0]], r"waypoints\[0\] must be \[x, y, yaw, stop\]"),
        ([[0, 0, 0, 1], [1.0, "a", 0.0, 1.0]], r"waypoints\[1\] must be"),
        ([[1.0, 2.0, 0.0, -1.0]], r"waypoints\[0\] = .* stop >= 0"),
    ],
)
def test_bad_waypoints_are_named(raw, match):
    with pytest.raises(ParameterError, match=match):
        waypoints_from_param(raw, "/karl/patrol_route/waypoints")


class FakeMoveBase(Node):
    """Succeeds each goal after 1 s; records (time received, x, y)."""

    def __init__(self, runtime) -> None:
        super().__init__(runtime, "move_base", "/karl")
        self.goals: list[tuple[float, float, float]] = []
        self.server = self.create_action_server(
            move_base_msgs.MoveBase, "move_base", goal_callback=self._goal
        )
        self.done_at = None
        self.create_timer(0.1, self._tick)

    def _goal(self) -> None:
        g = self.server.accept_new_goal()
        p = g.target_pose.pose.position
        self.goals.append((self.now(), p.x, p.y))
        self.done_at = self.now() + 1.0

    def _tick(self) -> None:
        if self.done_at is not None and self.now() >= self.done_at - 1e-9:
            self.done_at = None
            self.server.set_succeeded(move_base_msgs.MoveBase.Result())


def test_the_route_is_driven_in_order_with_its_stops_and_loops():
    rt = Runtime(seed=0)
    mb = FakeMoveBase(rt)
    route = PatrolRoute(
        rt,
        namespace="/karl",
        params={"waypoints": [[1.0, 0.0, 0.0, 2.0], [2.0, 0.0, 0.0, 0.0]], "start_delay": 0.5},
    )
    rt.run(duration=8.0)
    xs = [x for _, x, _ in mb.goals]
    assert xs[:4] == [1.0, 2.0, 1.0, 2.0]
    t = [t for t, _, _ in mb.goals]
    assert t[0] == pytest.approx(0.5, abs=0.15)
    assert t[1] - t[0] == pytest.approx(1.0 + 2.0, abs=0.25)  # 1 s driving + 2 s stop
    assert t[2] - t[1] == pytest.approx(1.0, abs=0.25)  # no stop at the second
    assert route.outcomes[0][:2] == (0, 3)
