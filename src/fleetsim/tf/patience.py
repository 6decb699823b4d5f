"""Patience with transforms that are not there yet.

In the first moments of a run a node's first messages come before the transforms it needs: the
localization's ``map -> odom`` follows the first ground truth or scan, a static transform
publisher's first message follows its first period. ROS waits for them instead of complaining:
``tf2_ros::MessageFilter`` holds a message until its transform arrives, ``waitForTransform``
blocks, and costmap_2d waits for ``global_frame -> robot_base_frame`` before it starts, warning
only after 5 s ("Timed out waiting for transform ... to become available before running
costmap"). `TransformPatience` gives a node that rule for any lookup: a failing lookup is
reported only once it has kept failing for ``grace`` seconds of sim time; a success forgets it.
"""

from __future__ import annotations

#: sim seconds a transform may stay missing before it is reported (costmap_2d's 5 s)
GRACE = 5.0


class TransformPatience:
    """When each failing lookup (by key) began to fail, in sim seconds."""

    __slots__ = ("_since", "grace")

    def __init__(self, grace: float = GRACE) -> None:
        if not grace >= 0.0:
            raise ValueError(f"grace must be >= 0 s, got {grace!r}")
        self.grace = grace
        self._since: dict[str, float] = {}

    def missing_too_long(self, key: str, now: float) -> bool:
        """Note a failure of ``key`` at ``now``; True once it has failed for ``grace`` s."""
        since = self._since.setdefault(key, now)
        return now - since >= self.grace

    def missing_for(self, key: str, now: float) -> float:
        """How long ``key`` has been failing, s (0 when it is not failing)."""
        since = self._since.get(key)
        return 0.0 if since is None else now - since

    def found(self, key: str) -> None:
        """``key`` succeeded: a later failure starts a new wait."""
        if self._since:  # the common case, nothing failing, costs one truth test
            self._since.pop(key, None)
