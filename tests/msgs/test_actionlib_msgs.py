from __future__ import annotations

from fleetsim.msgs import actionlib_msgs


def test_status_constants_are_ros1():
    s = actionlib_msgs.GoalStatus
    names = ["PENDING", "ACTIVE", "PREEMPTED", "SUCCEEDED", "ABORTED", "REJECTED"]
    names += ["PREEMPTING", "RECALLING", "RECALLED", "LOST"]
    assert [getattr(s, n) for n in names] == list(range(10))
    assert [c[0] for c in s.__msgconsts__] == names
    assert actionlib_msgs.GoalStatus().status == s.PENDING
    assert actionlib_msgs.GoalStatusArray().status_list == []
