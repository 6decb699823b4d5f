from __future__ import annotations

from fleetsim.msgs import deserialize, geometry_msgs, serialize, std_msgs, visualization_msgs


def test_marker_constants_and_round_trip():
    m = visualization_msgs.Marker
    assert (m.ARROW, m.LINE_STRIP, m.TEXT_VIEW_FACING, m.DELETEALL) == (0, 4, 9, 3)
    marker = m(ns="plan", id=2, type=m.LINE_STRIP, points=[geometry_msgs.Point(1, 2, 0)])
    marker.color = std_msgs.ColorRGBA(0.0, 1.0, 0.0, 1.0)
    arr = visualization_msgs.MarkerArray(markers=[marker])
    back = deserialize(serialize(arr), "visualization_msgs/MarkerArray")
    assert back.markers[0].points[0].y == 2.0 and back.markers[0].color.g == 1.0
