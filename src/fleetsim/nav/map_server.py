"""The ``map_server`` and ``map_saver`` nodes (ROS 1 map_server package).

``map_server`` takes the map as its first argument, as ROS does: ``args="willow.yaml"`` (a map
YAML) or the legacy ``args="willow.png 0.1"`` (an image and its resolution; origin 0, negate 0,
thresholds 0.65 / 0.196, trinary). It publishes the map once, latched, on ``map``
(nav_msgs/OccupancyGrid) and ``map_metadata`` (nav_msgs/MapMetaData) and answers ``static_map``
(nav_msgs/GetMap). ``~frame_id`` (default ``map``) is the map's frame; a leading slash is
dropped, since tf frame ids carry none.

``map_saver`` (``args="-f NAME [--occ 65] [--free 25]"``) subscribes to ``map`` and writes
``NAME.pgm`` + ``NAME.yaml`` from the first map it receives, as ROS's map_saver does before it
exits; `MapSaver.saved` holds the two paths once written. With ``~save_on_shutdown`` (a
fleetsim addition, for maps that grow during a run such as slam_gmapping's) it keeps the latest
map instead and writes it when the run ends.

`grid_msg_from_map` and `map_from_grid_msg` convert between `OccupancyMap` arrays and the
message; the costmap wrapper uses them too.
"""

from __future__ import annotations

import math
import shlex
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from fleetsim.msgs import geometry_msgs, nav_msgs, std_msgs
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.nav.errors import MapError
from fleetsim.nav.map_io import OccupancyMap, load_map, load_map_image, save_map
from fleetsim.runtime import Node, param
from fleetsim.tf.names import normalize_frame

_USAGE = "map_server <map.yaml>  or (deprecated)  map_server <map image> <resolution>"


def grid_msg_from_map(
    occupancy: OccupancyMap, frame_id: str = "map", stamp: Time | None = None
) -> nav_msgs.OccupancyGrid:
    """An OccupancyGrid message of ``occupancy`` (data row-major, row 0 at the origin's y)."""
    stamp = stamp if stamp is not None else Time()
    ox, oy, oyaw = occupancy.origin
    info = nav_msgs.MapMetaData(
        map_load_time=stamp,
        resolution=float(occupancy.resolution),
        width=occupancy.width,
        height=occupancy.height,
        origin=geometry_msgs.Pose(
            position=geometry_msgs.Point(x=float(ox), y=float(oy), z=0.0),
            orientation=geometry_msgs.Quaternion(
                x=0.0, y=0.0, z=math.sin(oyaw / 2.0), w=math.cos(oyaw / 2.0)
            ),
        ),
    )
    return nav_msgs.OccupancyGrid(
        header=std_msgs.Header(stamp=stamp, frame_id=frame_id),
        info=info,
        data=np.ascontiguousarray(occupancy.data, dtype=np.int8).ravel(),
    )


def map_from_grid_msg(msg: nav_msgs.OccupancyGrid, where: str = "map") -> OccupancyMap:
    """The arrays of an OccupancyGrid message; `MapError` if its size and data disagree."""
    info = msg.info
    w, h = int(info.width), int(info.height)
    data = np.asarray(msg.data, dtype=np.int8)
    if data.size != w * h:
        raise MapError(
            f"{where}: OccupancyGrid data holds {data.size} cells but info says {w} x {h} = "
            f"{w * h}; the publisher must fill data row by row"
        )
    res = float(info.resolution)
    if not (res > 0 and math.isfinite(res)):
        raise MapError(f"{where}: OccupancyGrid resolution must be > 0 m, got {res!r}")
    q = info.origin.orientation
    yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
    return OccupancyMap(
        data=data.reshape(h, w),
        resolution=res,
        origin=(float(info.origin.position.x), float(info.origin.position.y), yaw),
    )


def _tokens(args: Sequence[str] | str) -> list[str]:
    """Node args as tokens: a list as given, or one string split as a shell would."""
    if isinstance(args, str):
        return shlex.split(args)
    out: list[str] = []
    for a in args:
        out.extend(shlex.split(str(a)))
    return out


@dataclass(frozen=True)
class MapServerParams:
    """``map_server`` private parameters."""

    frame_id: str = param("map", help="frame of the published map (a leading '/' is dropped)")


class MapServer(Node):
    """Loads one map (YAML or legacy image + resolution) and serves it, latched.

    Parameters
    ----------
    map_file : the map YAML (or image, with ``resolution``); when omitted, the node's ``args``
        are read as on the ROS command line.
    resolution : metres per pixel for the legacy image form.
    """

    Params = MapServerParams

    def __init__(
        self,
        runtime,
        name: str = "map_server",
        namespace: str = "/",
        *,
        map_file: str | Path | None = None,
        resolution: float | None = None,
        **kw: Any,
    ) -> None:
        super().__init__(runtime, name, namespace, **kw)
        self.frame_id = normalize_frame(self.params.frame_id)
        self.map = self._load(map_file, resolution)
        stamp = self.now_msg()
        self.grid_msg = grid_msg_from_map(self.map, self.frame_id, stamp)
        self.metadata_pub = self.create_publisher(
            nav_msgs.MapMetaData, "map_metadata", queue_size=1, latch=True
        )
        self.map_pub = self.create_publisher(
            nav_msgs.OccupancyGrid, "map", queue_size=1, latch=True
        )
        self.create_service(nav_msgs.GetMap, "static_map", self.on_static_map)
        self.metadata_pub.publish(self.grid_msg.info)
        self.map_pub.publish(self.grid_msg)
        self.get_logger().info(
            f"read a {self.map.width} x {self.map.height} map @ {self.map.resolution:.3f} m/cell"
        )

    def _load(self, map_file: str | Path | None, resolution: float | None) -> OccupancyMap:
        if map_file is not None:
            if resolution is not None:
                return load_map_image(map_file, resolution)
            return load_map(map_file)
        tokens = _tokens(self.args)
        if len(tokens) == 1:
            return load_map(tokens[0])
        if len(tokens) == 2:
            try:
                res = float(tokens[1])
            except ValueError:
                raise MapError(
                    f"{self.full_name}: the resolution argument '{tokens[1]}' is not a number; "
                    f"usage: {_USAGE}"
                ) from None
            self.get_logger().warning(
                "the 'map_server IMAGE RESOLUTION' form is deprecated; use a map YAML file"
            )
            return load_map_image(tokens[0], res)
        raise MapError(
            f"{self.full_name}: expected a map file argument, got {tokens!r}; usage: {_USAGE}"
        )

    def on_static_map(self, req: Any) -> Any:
        return nav_msgs.GetMap.Response(map=self.grid_msg)


_SAVER_USAGE = "map_saver [--occ <threshold_occupied>] [--free <threshold_free>] [-f <mapname>]"


def saver_options(tokens: Sequence[str], where: str = "map_saver") -> tuple[str, int, int]:
    """Parse map_saver's arguments: ``(map name, occupied threshold, free threshold)``."""
    name, occ, free = "map", 65, 25
    it = iter(tokens)
    for tok in it:
        if tok not in ("-f", "--occ", "--free"):
            raise MapError(f"{where}: unknown argument '{tok}'; usage: {_SAVER_USAGE}")
        value = next(it, None)
        if value is None:
            raise MapError(f"{where}: '{tok}' needs a value; usage: {_SAVER_USAGE}")
        if tok == "-f":
            name = value
            continue
        try:
            number = int(value)
        except ValueError:
            raise MapError(f"{where}: '{tok} {value}': the threshold must be an integer") from None
        if not 0 <= number <= 100:
            raise MapError(f"{where}: '{tok} {value}': thresholds are in [0, 100]")
        if tok == "--occ":
            occ = number
        else:
            free = number
    if free >= occ:
        raise MapError(f"{where}: --free ({free}) must be below --occ ({occ})")
    return name, occ, free


@dataclass(frozen=True)
class MapSaverParams:
    """``map_saver`` private parameters."""

    save_on_shutdown: bool = param(
        False, help="keep the latest map and write it when the run ends (fleetsim addition)"
    )


class MapSaver(Node):
    """Writes the first map received on ``map`` as ``<name>.pgm`` + ``<name>.yaml``."""

    Params = MapSaverParams

    def __init__(self, runtime, name: str = "map_saver", namespace: str = "/", **kw: Any) -> None:
        super().__init__(runtime, name, namespace, **kw)
        self.map_name, self.occupied, self.free = saver_options(_tokens(self.args), self.full_name)
        folder = Path(self.map_name).parent
        if not folder.is_dir():
            # said now, not when the map comes (or at shutdown, after a whole exploration)
            raise MapError(
                f"{self.full_name}: -f {self.map_name}: the directory {folder} does not exist "
                "(map_saver does not create it)"
            )
        self.saved: tuple[Path, Path] | None = None
        self._latest: nav_msgs.OccupancyGrid | None = None
        self._sub = self.create_subscription(nav_msgs.OccupancyGrid, "map", self.on_map, 1)
        if self.params.save_on_shutdown:
            runtime.on_shutdown(self.save_latest)
        self.get_logger().info(f"waiting for the map on {self.resolve_name('map')}")

    def on_map(self, msg: nav_msgs.OccupancyGrid) -> None:
        if self.params.save_on_shutdown:
            self._latest = msg
            return
        self._save(msg)

    def save_latest(self) -> None:
        """Write the latest map received (``save_on_shutdown``); a warning if none came."""
        if self._latest is None:
            self.get_logger().warning(
                f"no map received on {self.resolve_name('map')}; nothing saved"
            )
            return
        self._save(self._latest)

    def _save(self, msg: nav_msgs.OccupancyGrid) -> None:
        if self.saved is not None:
            return
        occupancy = map_from_grid_msg(msg, f"{self.full_name}: {self.resolve_name('map')}")
        self.saved = save_map(
            occupancy, self.map_name, occupied_threshold=self.occupied, free_threshold=self.free
        )
        self._sub.destroy()
        self.get_logger().info(f"wrote {self.saved[0]} and {self.saved[1]}")
