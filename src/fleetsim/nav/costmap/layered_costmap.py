"""The layered costmap (costmap_2d's LayeredCostmap + Costmap2DROS's parameters).

`LayeredCostmap.from_params` reads a costmap's private namespace (``global_costmap`` or
``local_costmap`` as move_base sees it) with costmap_2d's names and defaults, in either form:

* ``plugins: [{name: ..., type: costmap_2d::StaticLayer}, ...]`` - layers in that order, each
  reading its own ``<name>/`` sub-namespace;
* no ``plugins`` key (pre-Hydro style) - costmap_2d's implicit stack: ``static_layer`` when
  ``static_map`` is true, ``obstacle_layer`` (a VoxelLayer when ``map_type: voxel``), then
  ``inflation_layer``; the top-level keys those layers used to read (obstacle_range,
  observation_sources and its sources, inflation_radius, ...) are moved into the layers'
  namespaces, overriding what is there, exactly as costmap_2d's loadOldParameters does.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Any

import numpy as np

from fleetsim.errors import did_you_mean
from fleetsim.nav.costmap.costmap_2d import FREE_SPACE, NO_INFORMATION, Costmap2D, lookup_bytes
from fleetsim.nav.costmap.footprint import (
    footprint_from_param,
    footprint_from_radius,
    footprint_radii,
    padded_footprint,
)
from fleetsim.nav.costmap.inflation_layer import InflationLayer
from fleetsim.nav.costmap.layer import Bounds, Layer
from fleetsim.nav.costmap.obstacle_layer import ObstacleLayer
from fleetsim.nav.costmap.robots_layer import RobotsLayer
from fleetsim.nav.costmap.static_layer import StaticLayer
from fleetsim.nav.costmap.voxel_layer import VoxelLayer
from fleetsim.nav.errors import CostmapError
from fleetsim.nav.map_io import OccupancyMap
from fleetsim.runtime import load_params, param
from fleetsim.runtime.param_tree import ParamDict

_log = logging.getLogger("fleetsim.nav.costmap")

#: costmap_2d plugin type -> layer class (one line per plugin kind)
LAYER_TYPES: dict[str, type[Layer]] = {
    "costmap_2d::StaticLayer": StaticLayer,
    "costmap_2d::ObstacleLayer": ObstacleLayer,
    "costmap_2d::VoxelLayer": VoxelLayer,
    "costmap_2d::InflationLayer": InflationLayer,
    "fleetsim::RobotsLayer": RobotsLayer,
}


@dataclass(frozen=True)
class CostmapParams:
    """Parameters of ``costmap_2d::Costmap2DROS`` (the costmap's own namespace)."""

    global_frame: str = param("map", help="frame the costmap lives in")
    robot_base_frame: str = param("base_link", help="the robot's base frame")
    update_frequency: float = param(5.0, unit="Hz", range=(0.0, None), help="map update rate")
    publish_frequency: float = param(0.0, unit="Hz", range=(0.0, None), help="publish rate")
    transform_tolerance: float = param(
        0.3, unit="s", range=(0.0, None), help="tolerated tf delay before the map goes stale"
    )
    static_map: bool = param(True, help="pre-Hydro form: start with a static_layer")
    rolling_window: bool = param(False, help="keep the map centred on the robot")
    always_send_full_costmap: bool = param(False, help="publish the whole map on every update")
    width: float = param(10.0, unit="m", range=(0.0, None), help="map width")
    height: float = param(10.0, unit="m", range=(0.0, None), help="map height")
    resolution: float = param(0.05, unit="m/cell", range=(1e-6, None), help="cell size")
    origin_x: float = param(0.0, unit="m", help="x of the map's lower-left corner")
    origin_y: float = param(0.0, unit="m", help="y of the map's lower-left corner")
    map_type: str = param(
        "costmap", choices=("costmap", "voxel"), help="pre-Hydro form: 2-D or voxel obstacles"
    )
    track_unknown_space: bool = param(False, help="cells start unknown rather than free")
    footprint: str | list = param("[]", help="robot polygon [[x, y], ...] in the base frame")
    robot_radius: float = param(
        0.46, unit="m", range=(0.0, None), help="circular robot when no footprint is given"
    )
    footprint_padding: float = param(0.01, unit="m", help="added to the footprint outward")
    plugins: list | None = param(None, help="layers in order: [{name, type}, ...]")


# keys of the pre-Hydro form moved into each implicit layer: (key, delete from parent)
_MOVED_STATIC = ("map_topic", "unknown_cost_value", "lethal_cost_threshold")
_MOVED_VOXEL = (
    "origin_z",
    "z_resolution",
    "z_voxels",
    "mark_threshold",
    "unknown_threshold",
    "publish_voxel_map",
)
_MOVED_OBSTACLE = ("max_obstacle_height", "raytrace_range", "obstacle_range")
_MOVED_INFLATION = ("cost_scaling_factor", "inflation_radius")
_PRE_HYDRO_KEYS = (
    *_MOVED_STATIC, *_MOVED_VOXEL, *_MOVED_OBSTACLE, *_MOVED_INFLATION, "observation_sources"
)  # fmt: skip
_SEARCHED = frozenset({"obstacle_range", "raytrace_range"})  # read by sources via searchParam


def _layer_specs(ns: dict[str, Any], p: CostmapParams) -> tuple[list[tuple[str, str]], set[str]]:
    """Plugin (name, type) pairs, rewriting ``ns`` in place for the pre-Hydro form.

    Returns the specs and the top-level keys consumed by layers.
    """
    if p.plugins is not None:
        specs = []
        for i, entry in enumerate(p.plugins):
            if not isinstance(entry, dict) or "name" not in entry or "type" not in entry:
                raise CostmapError(
                    f"plugins[{i}] must be a mapping with 'name' and 'type', got {entry!r}"
                )
            specs.append((str(entry["name"]), str(entry["type"])))
        # a common file loaded into both costmaps (the manual's nav_stack.launch) leaves the
        # pre-Hydro form's keys beside a plugins list; ROS's layers read their own namespaces
        # and leave those unread without a word: said once, not warned about as unknown
        old = {"map_type", *_PRE_HYDRO_KEYS}
        old |= set(str(ns.get("observation_sources", "")).split())
        unread = sorted(k for k in old if k in ns and k not in _SEARCHED)
        if unread:
            _log.info(
                "'plugins' is set: the pre-Hydro keys %s are not read (each layer reads its own "
                "namespace)",
                ", ".join(unread),
            )
        return specs, set(unread)
    _log.info("no 'plugins' parameter: loading the pre-Hydro static/obstacle/inflation stack")
    consumed: set[str] = set()

    def move(layer: str, keys: tuple[str, ...] | list[str]) -> None:
        sub = ParamDict.copy_of(ns.get(layer))
        origins = getattr(ns, "origins", None) or {}
        for key in keys:
            if key in ns:
                sub[key] = ns[key]
                consumed.add(key)
                if key in origins:
                    sub.origins[key] = origins[key]
                else:
                    sub.origins.pop(key, None)
        ns[layer] = sub

    specs = []
    if p.static_map:
        specs.append(("static_layer", "costmap_2d::StaticLayer"))
        move("static_layer", [*_MOVED_STATIC, "track_unknown_space"])
    voxel = p.map_type == "voxel"
    specs.append(
        ("obstacle_layer", "costmap_2d::VoxelLayer" if voxel else "costmap_2d::ObstacleLayer")
    )
    sources = str(ns.get("observation_sources", "")).split()
    moved = [*(_MOVED_VOXEL if voxel else ()), *_MOVED_OBSTACLE, "track_unknown_space"]
    move("obstacle_layer", [*moved, *sources, "observation_sources"])
    specs.append(("inflation_layer", "costmap_2d::InflationLayer"))
    move("inflation_layer", _MOVED_INFLATION)
    consumed.discard("track_unknown_space")
    return specs, consumed


def robot_footprint(p: CostmapParams, where: str = "") -> np.ndarray:
    """The padded footprint polygon from ``footprint`` or ``robot_radius``: (K, 2) m."""
    raw = p.footprint
    empty = (isinstance(raw, str) and raw.strip() in ("", "[]")) or (
        isinstance(raw, list) and len(raw) == 0
    )
    if empty:
        fp = footprint_from_radius(p.robot_radius)
    else:
        fp = footprint_from_param(raw, f"{where}/footprint" if where else "footprint")
    return padded_footprint(fp, p.footprint_padding)


class LayeredCostmap:
    """A master `Costmap2D` computed from an ordered list of layers."""

    def __init__(
        self,
        params: CostmapParams | None = None,
        layers: list[Layer] | None = None,
        name: str = "costmap",
    ) -> None:
        self.params = p = params or CostmapParams()
        self.name = name
        self.rolling_window = p.rolling_window
        self.track_unknown_space = p.track_unknown_space
        self.costmap = Costmap2D(
            int(p.width / p.resolution + 1e-9),
            int(p.height / p.resolution + 1e-9),
            p.resolution,
            p.origin_x,
            p.origin_y,
            NO_INFORMATION if p.track_unknown_space else FREE_SPACE,
        )
        self.footprint = robot_footprint(p, name)
        self.inscribed_radius, self.circumscribed_radius = footprint_radii(self.footprint)
        self.layers: list[Layer] = []
        for layer in layers or []:
            self.add_layer(layer)

    @classmethod
    def from_params(cls, ns: dict[str, Any] | None, name: str = "costmap") -> LayeredCostmap:
        """Build from a costmap namespace dict (see the module docstring for both forms)."""
        ns = ParamDict.copy_of(ns)  # the pre-Hydro keys move into it (_layer_specs)
        plugin_names = {str(e.get("name")) for e in ns.get("plugins") or [] if isinstance(e, dict)}
        first = load_params(
            CostmapParams, ns, name, ignore=frozenset(ns.keys()), logger=_log
        )  # parsed once for the form; warnings come below
        specs, consumed = _layer_specs(ns, first)
        sub_namespaces = {n for n, _ in specs} | plugin_names
        ignore = frozenset(sub_namespaces | consumed | _SEARCHED)
        # the pre-Hydro form's layer keys are read at this level too: a misspelled one
        # (``inflation_raduis``) is offered the key its layer reads
        layer_keys = () if first.plugins is not None else _PRE_HYDRO_KEYS
        params = load_params(
            CostmapParams, ns, name, ignore=ignore, logger=_log, also_known=layer_keys
        )
        parent = {k: v for k, v in ns.items() if not isinstance(v, dict)}
        layers: list[Layer] = []
        for lname, ltype in specs:
            kind = LAYER_TYPES.get(ltype)
            if kind is None:
                raise CostmapError(
                    f"{name}: plugin '{lname}' has unknown type '{ltype}'"
                    f"{did_you_mean(ltype, LAYER_TYPES)}; known: {', '.join(LAYER_TYPES)}"
                )
            lns = ns.get(lname) or {}
            if not isinstance(lns, dict):
                raise CostmapError(f"{name}/{lname}: layer parameters must be a mapping")
            if issubclass(kind, ObstacleLayer):
                layers.append(kind.from_namespace(lname, ParamDict.copy_of(lns), parent, name))
            else:
                lp = load_params(kind.Params, lns, f"{name}/{lname}", logger=_log)  # type: ignore[attr-defined]
                layers.append(kind(lname, lp))  # type: ignore[call-arg]
        return cls(params, layers, name)

    # -- structure ------------------------------------------------------------------------------
    def add_layer(self, layer: Layer) -> None:
        layer.initialize(self)
        layer.match_size()
        layer.on_footprint_changed()
        self.layers.append(layer)

    def layer(self, name: str) -> Layer:
        for layer in self.layers:
            if layer.name == name:
                return layer
        names = [la.name for la in self.layers]
        raise CostmapError(f"{self.name}: no layer '{name}'{did_you_mean(name, names)}")

    def resize_map(self, size_x: int, size_y: int, resolution: float, ox: float, oy: float):
        self.costmap.resize_map(size_x, size_y, resolution, ox, oy)
        for layer in self.layers:
            layer.match_size()

    def set_footprint(self, footprint: np.ndarray) -> None:
        """Replace the (already padded) footprint polygon: (K, 2) m, K >= 3."""
        fp = footprint_from_param(np.asarray(footprint).tolist(), f"{self.name}/footprint")
        self.footprint = fp
        self.inscribed_radius, self.circumscribed_radius = footprint_radii(fp)
        for layer in self.layers:
            layer.on_footprint_changed()

    # -- data -----------------------------------------------------------------------------------
    def set_map(self, occupancy: OccupancyMap) -> None:
        """Hand a map to every static layer (the ``map`` topic)."""
        for layer in self.layers:
            if isinstance(layer, StaticLayer):
                layer.set_map(occupancy)

    def add_observation(self, source: str, origin: Any, points: Any, stamp: float = 0.0):
        """Feed a reading to every obstacle layer that has ``source``; see ObstacleLayer."""
        targets = [
            la for la in self.layers if isinstance(la, ObstacleLayer) and source in la.buffers
        ]
        if not targets:
            raise CostmapError(f"{self.name}: no obstacle layer has observation source '{source}'")
        for layer in targets:
            layer.add_observation(source, origin, points, stamp)

    def reset_layers(self) -> None:
        """Forget all sensed data and recompute everything (clear_costmaps)."""
        self.costmap.reset_map()
        for layer in self.layers:
            layer.reset()

    def update_map(self, robot_x: float, robot_y: float, robot_yaw: float) -> tuple[int, ...]:
        """One costmap update at the robot pose; returns the recomputed cells (x0, y0, xn, yn)."""
        m = self.costmap
        if self.rolling_window:
            m.update_origin(robot_x - m.size_in_meters_x / 2, robot_y - m.size_in_meters_y / 2)
        bounds = Bounds()
        for layer in self.layers:
            if layer.enabled:
                layer.update_bounds(robot_x, robot_y, robot_yaw, bounds)
        if bounds.empty:
            return (0, 0, 0, 0)
        res = m.resolution
        x0 = max(0, int(np.floor((bounds.min_x - m.origin_x) / res)))
        y0 = max(0, int(np.floor((bounds.min_y - m.origin_y) / res)))
        xn = min(m.size_x, int(np.floor((bounds.max_x - m.origin_x) / res)) + 1)
        yn = min(m.size_y, int(np.floor((bounds.max_y - m.origin_y) / res)) + 1)
        if xn <= x0 or yn <= y0:
            return (0, 0, 0, 0)
        m.reset_map(x0, y0, xn, yn)
        for layer in self.layers:
            if layer.enabled:
                layer.update_costs(m, x0, y0, xn, yn)
        return (x0, y0, xn, yn)

    def occupancy_grid(self) -> OccupancyMap:
        """The master grid as costmap_2d publishes it (0..100, -1 unknown)."""
        return OccupancyMap(
            data=occupancy_from_costs(self.costmap.costs),
            resolution=self.costmap.resolution,
            origin=(self.costmap.origin_x, self.costmap.origin_y, 0.0),
        )


def _publish_table() -> np.ndarray:
    table = np.empty(256, dtype=np.int8)
    i = np.arange(1, 253)
    table[0] = 0
    table[1:253] = 1 + (97 * (i - 1)) // 251
    table[253], table[254], table[255] = 99, 100, -1
    return table


#: costmap_2d's publisher translation, cost (0..255) -> occupancy value
_PUBLISHED = _publish_table()
#: its inverse, occupancy value as an unsigned byte -> the least cost published as it (values
#: above 100 read as lethal, negative ones as unknown)
_UNPUBLISHED = np.full(256, 254, dtype=np.uint8)
_UNPUBLISHED[128:] = 255
for _cost in range(255, -1, -1):  # from the top, so each value keeps its least cost
    _UNPUBLISHED[int(_PUBLISHED[_cost]) & 0xFF] = _cost


def occupancy_from_costs(costs: np.ndarray) -> np.ndarray:
    """costmap_2d's publisher translation: 0->0, 1..252->1..97, 253->99, 254->100, 255->-1."""
    return lookup_bytes(np.asarray(costs, dtype=np.uint8), _PUBLISHED)


def costs_from_published(data: np.ndarray) -> np.ndarray:
    """(H, W) uint8 costs of a published costmap grid (H, W) int8: the inverse of
    `occupancy_from_costs`, each value read as the least cost that publishes as it (-1 -> 255
    unknown, 99 -> 253 inscribed, 100 -> 254 lethal)."""
    return lookup_bytes(np.asarray(data), _UNPUBLISHED)
