"""explore_lite's ``~frontiers`` markers (``visualize``): each frontier's cells as red points."""

from __future__ import annotations

from collections.abc import Sequence

from fleetsim.msgs import geometry_msgs, std_msgs, visualization_msgs

from .frontier_search import Frontier


def frontier_markers(
    frontiers: Sequence[Frontier], header: std_msgs.Header
) -> visualization_msgs.MarkerArray:
    """A MarkerArray that clears the previous markers and draws each frontier's cells."""
    markers = [visualization_msgs.Marker(header=header, action=visualization_msgs.Marker.DELETEALL)]
    for i, f in enumerate(frontiers):
        markers.append(
            visualization_msgs.Marker(
                header=header,
                ns="frontiers",
                id=i,
                type=visualization_msgs.Marker.POINTS,
                scale=geometry_msgs.Vector3(x=0.1, y=0.1, z=0.1),
                color=std_msgs.ColorRGBA(r=1.0, g=0.0, b=0.0, a=1.0),
                points=[geometry_msgs.Point(x=float(x), y=float(y), z=0.0) for x, y in f.points],
            )
        )
    return visualization_msgs.MarkerArray(markers=markers)
