"""slam_gmapping's parameters, declared once: ROS name, gmapping's *code* default, unit, range.

The defaults are those ``SlamGMapping::init()`` uses when a parameter is absent
(``gmapping/src/slam_gmapping.cpp``), not the wiki's: ``maxUrange`` and ``maxRange`` default to
the first scan's ``range_max - 0.01`` (held as None here), ``temporalUpdate`` is off (-1 in ROS,
None here), ``srt``/``stt`` are 0.2 and ``angularUpdate`` 0.5. ``srt`` scales *rotation* noise by
translation and ``str`` *translation* noise by rotation, as ``motionmodel.cpp`` does.

The four ``ll*``/``la*`` sampling parameters are read by gmapping but only used by
``ScanMatcher::likelihood()``, which slam_gmapping never calls; they are accepted, with a
warning that they have no effect when set to anything but their default (`NO_EFFECT`; at the
default, as the manual's launch file sets them, the same note at INFO level, so that a normal
run stays free of warnings).
"""

from __future__ import annotations

import builtins
import logging
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from fleetsim.errors import ParameterError
from fleetsim.runtime.params import ParamDict, load_params, param

#: accepted, but gmapping never uses them on the path slam_gmapping runs
NO_EFFECT = ("llsamplerange", "llsamplestep", "lasamplerange", "lasamplestep")

#: ROS writes -1 for "unset" here; held as None
UNSET_WHEN_NEGATIVE = ("temporalUpdate", "maxRange", "maxUrange")


@dataclass(frozen=True)
class GmappingParams:
    """Parameters of ``gmapping/slam_gmapping`` (ROS names, gmapping's code defaults).

    The field ``str`` (gmapping's name) shadows the builtin in this class body, hence
    ``builtins.str`` for the frame names.
    """

    # --- frames and rates ---
    base_frame: builtins.str = param("base_link", help="robot base frame (tf_prefix applied)")
    map_frame: builtins.str = param("map", help="frame of the map (tf_prefix applied)")
    odom_frame: builtins.str = param("odom", help="odometry frame (tf_prefix applied)")
    throttle_scans: int = param(1, range=(1, None), help="process every n-th scan")
    map_update_interval: float = param(
        5.0, unit="s", range=(0.0, None), help="scan time between two publications of the map"
    )
    transform_publish_period: float = param(
        0.05,
        unit="s",
        range=(0.0, None),
        help="period of the map->odom broadcast (0: off; capped at the simulator's rate)",
    )
    tf_delay: float | None = param(
        None,
        unit="s",
        range=(0.0, None),
        help="map->odom is dated this far ahead (None: transform_publish_period)",
    )
    # --- laser ---
    maxRange: float | None = param(
        None, unit="m", range=(0.0, None), help="beams beyond are dropped (None: range_max-0.01)"
    )
    maxUrange: float | None = param(
        None, unit="m", range=(0.0, None), help="usable range for matching (None: maxRange)"
    )
    # --- scan matcher ---
    minimumScore: float = param(
        0.0, range=(0.0, None), help="match score at or below which odometry is kept"
    )
    sigma: float = param(0.05, unit="m", range=(1e-9, None), help="score s += exp(-d^2/sigma)")
    kernelSize: int = param(1, range=(0, 10), help="cells searched around each endpoint")
    lstep: float = param(0.05, unit="m", range=(1e-9, None), help="initial translational step")
    astep: float = param(0.05, unit="rad", range=(1e-9, None), help="initial angular step")
    iterations: int = param(5, range=(0, 50), help="step halvings of the hill climber")
    lsigma: float = param(
        0.075, unit="m", range=(1e-9, None), help="likelihood l += -d^2/lsigma per beam"
    )
    ogain: float = param(3.0, range=(1e-9, None), help="smoothing of the weights")
    lskip: int = param(0, range=(0, None), help="use every (lskip+1)-th beam")
    continuous_score: bool = param(
        True,
        help="fleetsim addition: a beam scores its distance to the nearest hit capped at "
        "kernelSize*delta, so the score is continuous in the pose, and the hill climber's "
        "pose is refined below its last step (false: gmapping's score, 0 for a beam with no "
        "hit in its window, and its climber; see fleetsim.slam.scan_match)",
    )
    climb_skip: int = param(
        3,
        range=(0, None),
        help="fleetsim addition, with continuous_score: the hill climber scores every "
        "(climb_skip+1)-th of the beams lskip leaves, then Gauss-Newton steps of a "
        "point-to-line fit of all of them finish the match (the matcher ~2.5x faster; 0: "
        "every beam all the way and the parabola, gmapping's climber; see "
        "fleetsim.slam.scan_match and fleetsim.slam.scan_align)",
    )
    degeneracy_threshold: float = param(
        0.0,
        range=(0.0, None),
        help="fleetsim addition, with continuous_score: a direction of the match's translation "
        "on which the scan gives less information than this (in beams' worth of a hit on a "
        "wall square to it) keeps the motion model's sampled pose, as along a single wall in "
        "range, where the climber drifts (0: off, gmapping's matcher; see "
        "fleetsim.slam.scan_align.constrained_pose)",
    )
    # --- peers (fleetsim addition; see fleetsim.slam.peers) ---
    peer_frames: list = param(
        [],
        help="fleetsim addition: other robots' base frames (full tf names, e.g. "
        "hunter2/base_link); beams that end within peer_radius + peer_margin of one, found "
        "through tf at the scan's time, are left out of scan matching and the map (empty: off, "
        "gmapping's behaviour)",
    )
    peer_radius: float = param(
        0.35, unit="m", range=(0.0, None), help="radius of a disc covering a peer's body"
    )
    peer_margin: float = param(
        0.1,
        unit="m",
        range=(0.0, None),
        help="added to peer_radius for the error of the two robots' pose estimates",
    )
    # --- motion model ---
    srr: float = param(0.1, range=(0.0, None), help="translation noise from translation")
    srt: float = param(0.2, range=(0.0, None), help="rotation noise from translation")
    str: float = param(0.1, range=(0.0, None), help="translation noise from rotation")
    stt: float = param(0.2, range=(0.0, None), help="rotation noise from rotation")
    # --- update gating and filter ---
    linearUpdate: float = param(1.0, unit="m", range=(0.0, None), help="travel before an update")
    angularUpdate: float = param(
        0.5, unit="rad", range=(0.0, None), help="rotation before an update"
    )
    temporalUpdate: float | None = param(
        None, unit="s", range=(0.0, None), help="scan time before an update (None: off)"
    )
    resampleThreshold: float = param(
        0.5, range=(0.0, 1.0), help="resample when Neff < this * particles"
    )
    particles: int = param(30, range=(1, 10000), help="number of particles")
    # --- map ---
    xmin: float = param(-100.0, unit="m", help="initial map extent")
    ymin: float = param(-100.0, unit="m", help="initial map extent")
    xmax: float = param(100.0, unit="m", help="initial map extent")
    ymax: float = param(100.0, unit="m", help="initial map extent")
    delta: float = param(0.05, unit="m", range=(1e-4, 10.0), help="map resolution")
    occ_thresh: float = param(0.25, range=(0.0, 1.0), help="hit ratio above which a cell is 100")
    # --- read but never used by gmapping (NO_EFFECT) ---
    llsamplerange: float = param(0.01, unit="m", help="no effect (gmapping never uses it)")
    llsamplestep: float = param(0.01, unit="m", help="no effect (gmapping never uses it)")
    lasamplerange: float = param(0.005, unit="rad", help="no effect (gmapping never uses it)")
    lasamplestep: float = param(0.005, unit="rad", help="no effect (gmapping never uses it)")

    def __post_init__(self) -> None:
        for frame in self.peer_frames:
            if not isinstance(frame, builtins.str) or not frame.strip("/"):
                raise ParameterError(
                    f"slam_gmapping: peer_frames holds {frame!r}; give each peer's base frame "
                    "as a tf frame name, e.g. 'hunter2/base_link'"
                )
        if self.xmin >= self.xmax or self.ymin >= self.ymax:
            raise ParameterError(
                f"slam_gmapping: the map extent xmin..xmax = {self.xmin}..{self.xmax}, "
                f"ymin..ymax = {self.ymin}..{self.ymax} is empty; set xmin < xmax and ymin < ymax"
            )


def gmapping_params(
    mapping: Mapping[str, Any] | None, where: str = "slam_gmapping", logger: Any = None
) -> GmappingParams:
    """Validated `GmappingParams` from a ROS mapping; -1 means unset where ROS says so."""
    log = logger or logging.getLogger("fleetsim.slam")
    values = ParamDict.copy_of(mapping)  # keeps where each value was set, for messages
    for key in UNSET_WHEN_NEGATIVE:
        v = values.get(key)
        if isinstance(v, int | float) and not isinstance(v, bool) and v < 0:
            values[key] = None
    # a value changed from gmapping's default would silently do nothing: warn; the default
    # itself (what the manual's launch file sets) changes nothing either way: a note
    defaults = GmappingParams()
    for changed in (True, False):
        keys = [
            k for k in NO_EFFECT if k in values and (values[k] != getattr(defaults, k)) == changed
        ]
        if keys:
            (log.warning if changed else log.info)(
                "%s: parameter%s %s ha%s no effect: gmapping reads %s but never uses %s (only "
                "ScanMatcher::likelihood() does, which slam_gmapping does not call)",
                where,
                "s" if len(keys) > 1 else "",
                ", ".join(repr(k) for k in keys),
                "ve" if len(keys) > 1 else "s",
                "them" if len(keys) > 1 else "it",
                "them" if len(keys) > 1 else "it",
            )
    try:
        return load_params(GmappingParams, values, where=where, logger=log)
    except ParameterError as err:
        # __post_init__'s checks do not know the node: name it, as the others do
        text = str(err)
        if text.startswith("slam_gmapping: "):
            text = f"{where}: {text.removeprefix('slam_gmapping: ')}"
        raise ParameterError(text) from None
