"""Beams that end on a peer robot, left out of gmapping's matching and mapping (fleetsim addition).

Two robots that map the same rooms see each other. gmapping keeps every beam: a beam that ends
on the other robot's body is matched against the map like a wall (the scan matcher locks onto a
body that moves, and the robot's own estimate drifts with it) and is written into the map as an
obstacle (a robot standing in the other's view becomes lethal under itself in a merged map it
plans on). With ``peer_frames`` set, slam_gmapping looks each peer's base frame up in its own
base frame through tf at the scan's time, and `beams_clear_of_peers` leaves out the beams that
end within ``peer_radius + peer_margin`` of one, before scan matching and before the map update.

The peer's pose comes from tf, not from ground truth: the chain runs from this robot's base
through its own ``map -> odom`` (its SLAM estimate), the shared map frame (map_merge's world
frame, joined to each robot's map by its known initial pose) and the peer's ``map -> odom`` (the
peer's SLAM estimate). That is what a real multi-robot ROS system has; both robots' errors are
in it, which ``peer_margin`` covers. (The other source, collvoid's ``/position_share``, carries
the same localization estimates but is published only by robots running collvoid's
me_publisher; tf is there whenever the robots share a map.)
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from fleetsim.errors import ExtrapolationError, FleetsimError

#: s: how long a scan waits for a peer's tf to reach its time (the peer's odometry or map ->
#: odom a little behind this robot's) before it is matched with that peer's beams kept (warned)
PEER_PATIENCE = 0.2


def beams_clear_of_peers(
    ranges: np.ndarray,
    angles: np.ndarray,
    laser: np.ndarray,
    peers: np.ndarray,
    radius: float,
) -> np.ndarray:
    """Which beams end farther than ``radius`` from every peer.

    Parameters
    ----------
    ranges : (B,) m, the beams' ranges in the laser frame.
    angles : (B,) rad, the beams' angles in the laser frame.
    laser : (3,) the laser's pose ``(x m, y m, yaw rad)`` in the robot's base frame.
    peers : (K, 2) m, the peers' centres (their base frames' origins) in the base frame.
    radius : m, a peer's body radius plus the margin for the error of its pose.

    Returns
    -------
    (B,) bool: True for a beam kept (its endpoint is not on a peer).
    """
    keep = np.ones(len(ranges), dtype=bool)
    if len(peers) == 0 or len(ranges) == 0:
        return keep
    a = angles + laser[2]
    ex = laser[0] + ranges * np.cos(a)  # (B,) endpoints in the base frame
    ey = laser[1] + ranges * np.sin(a)
    for px, py in np.asarray(peers, dtype=float).reshape(-1, 2):
        keep &= np.hypot(ex - px, ey - py) > radius
    return keep


@dataclass
class PeerLookup:
    """Where the peers are at one scan's time, in the robot's base frame."""

    positions: np.ndarray  # (K, 2) m, the peers found
    wait: bool = False  # some peer's tf has not reached the scan's time yet: retry the scan
    skip: bool = False  # the scan is older than some peer's first transform (the start): drop it
    missing: dict[str, str] = field(default_factory=dict)  # frame -> why it is not in positions


def peers_in_base(
    buffer, base_frame: str, peer_frames: list[str], stamp: float, now: float, grace: float
) -> PeerLookup:
    """Look the peers' base frames up in ``base_frame`` at ``stamp`` (s) through tf.

    A peer whose tf is behind the scan makes the scan wait (``wait``) while the scan is younger
    than `PEER_PATIENCE`; a peer not in tf (yet) makes it wait until ``now`` passes ``grace``
    (s, the start: the peer's first transforms are on their way), and a scan older than the
    peer's first transforms is dropped then (``skip``: the scans of the first moments, before
    the peer's slam_gmapping published its first ``map -> odom``). After that the peer is
    ``missing``, with the reason: the caller keeps its beams and warns, naming the frame.
    """
    found = []
    out = PeerLookup(np.zeros((0, 2)))
    for frame in peer_frames:
        try:
            x, y, _ = buffer.lookup_pose2d(base_frame, frame, stamp)
        except ExtrapolationError as err:
            try:
                behind = buffer.latest_common_time(base_frame, frame) < stamp
            except FleetsimError:
                behind = False
            if behind and now - stamp < PEER_PATIENCE:
                out.wait = True
            elif not behind and now < grace:
                out.skip = True  # a scan from before the peer's first transforms (the start)
            else:
                out.missing[frame] = f"no pose of {frame} at the scan's time {stamp:.3f} s ({err})"
            continue
        except FleetsimError as err:
            if now < grace:
                out.wait = True
            else:
                out.missing[frame] = f"cannot find {frame} in {base_frame} ({err})"
            continue
        found.append((x, y))
    out.positions = np.array(found, dtype=float).reshape(-1, 2)
    return out
