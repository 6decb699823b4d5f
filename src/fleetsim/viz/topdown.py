"""`TopDownFigure`: draws a `Snapshot` with matplotlib (Agg) into an RGB array.

The axes fill the whole figure and show exactly the chosen extent, so world point ``(x, y)``
lands at pixel ``world_to_pixel(x, y)``; artists are made once and updated frame after frame,
which keeps long MP4 renders fast. Layers, bottom to top: map, trails, particle clouds, paths,
laser points, goals, robots (footprint filled in the robot's colour, a heading line), names.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg  # headless, no pyplot state
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Polygon

from fleetsim.errors import FleetsimError
from fleetsim.viz.robots import colour_of
from fleetsim.viz.scene_state import Snapshot

#: grey levels for the map: unknown cells, and free (0) to occupied (100) from white to black
UNKNOWN_GREY = 0.8
BACKGROUND = "#cdcdcd"


def grey_from_occupancy(data: np.ndarray) -> np.ndarray:
    """Grey levels in [0, 1] (1 = white = free) from int8 occupancy values, same shape.

    Values -1 (unknown) give `UNKNOWN_GREY`; 0..100 map linearly from 1 to 0.
    """
    d = np.asarray(data, dtype=float)
    grey = 1.0 - np.clip(d, 0.0, 100.0) / 100.0
    return np.where(d < 0, UNKNOWN_GREY, grey)


def _darker(rgb: tuple[float, float, float], f: float = 0.55) -> tuple[float, float, float]:
    return (rgb[0] * f, rgb[1] * f, rgb[2] * f)


class TopDownFigure:
    """A figure of ``width`` pixels showing ``extent = (xmin, xmax, ymin, ymax)`` metres.

    The height follows the extent's aspect ratio; both sizes are even (what H.264 needs).
    """

    def __init__(self, extent: tuple[float, float, float, float], width: int = 800) -> None:
        xmin, xmax, ymin, ymax = map(float, extent)
        if not (xmax > xmin and ymax > ymin) or not np.isfinite([xmin, xmax, ymin, ymax]).all():
            raise FleetsimError(f"render extent {extent} is empty; xmax > xmin and ymax > ymin")
        if width < 64:
            raise FleetsimError(f"render width must be >= 64 pixels, got {width}")
        self.extent = (xmin, xmax, ymin, ymax)
        self.width = int(width) // 2 * 2
        self.height = max(2, round(self.width * (ymax - ymin) / (xmax - xmin)) // 2 * 2)
        dpi = 100
        self.fig = Figure(figsize=(self.width / dpi, self.height / dpi), dpi=dpi)
        FigureCanvasAgg(self.fig)
        self.fig.patch.set_facecolor(BACKGROUND)
        ax = self.ax = self.fig.add_axes((0, 0, 1, 1))
        ax.set_axis_off()
        ax.set_xlim(xmin, xmax)
        ax.set_ylim(ymin, ymax)
        ax.set_aspect("auto")
        self._map_image: Any = None
        self._map_source: Any = None
        self._artists: dict[tuple, Any] = {}
        self._used: set[tuple] = set()
        self._scale = self.width / (xmax - xmin)  # pixels per metre
        self._time = ax.text(
            0.01, 0.99, "", transform=ax.transAxes, va="top", ha="left", fontsize=9, zorder=10,
            bbox={"facecolor": "white", "alpha": 0.7, "edgecolor": "none", "pad": 2},
        )  # fmt: skip

    def world_to_pixel(self, x: float, y: float) -> tuple[int, int]:
        """(column, row) of the pixel showing world point (x, y); row 0 is the top."""
        xmin, xmax, ymin, ymax = self.extent
        col = (x - xmin) / (xmax - xmin) * self.width
        row = (ymax - y) / (ymax - ymin) * self.height
        return int(np.floor(col)), int(np.floor(row))

    # -- artists ----------------------------------------------------------------------------
    def _line(self, key: tuple, **style: Any) -> Line2D:
        art = self._artists.get(key)
        if art is None:
            art = self._artists[key] = Line2D([], [], **style)
            self.ax.add_line(art)
        self._used.add(key)
        art.set_visible(True)
        return art

    def _polygon(self, key: tuple, xy: np.ndarray, **style: Any) -> Polygon:
        art = self._artists.get(key)
        if art is None:
            art = self._artists[key] = Polygon(xy, closed=True, **style)
            self.ax.add_patch(art)
        else:
            art.set_xy(xy)
        self._used.add(key)
        art.set_visible(True)
        return art

    def _text(self, key: tuple, x: float, y: float, s: str, **style: Any) -> Any:
        art = self._artists.get(key)
        if art is None:
            art = self._artists[key] = self.ax.text(x, y, s, **style)
        art.set_position((x, y))
        art.set_text(s)
        self._used.add(key)
        art.set_visible(True)
        return art

    def _draw_map(self, grid: Any) -> None:
        if grid is None or grid is self._map_source:
            return
        info = grid.info
        w, h = int(info.width), int(info.height)
        data = np.asarray(grid.data)
        if w * h == 0 or data.shape[0] != w * h:
            return
        img = grey_from_occupancy(data.reshape(h, w))
        x0, y0, res = info.origin.position.x, info.origin.position.y, info.resolution
        ext = (x0, x0 + w * res, y0, y0 + h * res)
        if self._map_image is None:
            self._map_image = self.ax.imshow(
                img, cmap="gray", vmin=0.0, vmax=1.0, origin="lower", extent=ext,
                interpolation="nearest", zorder=0,
            )  # fmt: skip
            self.ax.set_xlim(self.extent[0], self.extent[1])
            self.ax.set_ylim(self.extent[2], self.extent[3])
        else:
            self._map_image.set_data(img)
            self._map_image.set_extent(ext)
        self._map_source = grid

    # -- frames -----------------------------------------------------------------------------
    def draw(self, snap: Snapshot) -> np.ndarray:
        """Draw ``snap``; returns the frame as a (height, width, 3) uint8 RGB array."""
        self._used = set()
        self._draw_map(snap.map)
        index = {r.name: r.index for r in snap.robots}
        dot = max(1.0, 0.04 * self._scale)  # a 4 cm laser dot, at least a pixel
        for r in snap.robots:
            c = colour_of(r.index)
            if r.trail.shape[0] > 1:
                self._line(("trail", r.name), color=c, lw=1.5, alpha=0.6, zorder=2).set_data(
                    r.trail[:, 0], r.trail[:, 1]
                )
        for topic, poses in snap.particles.items():
            c = colour_of(index.get(topic.strip("/").split("/")[0], 0))
            self._line(
                ("particles", topic), color=c, ls="none", marker=".", ms=2, alpha=0.5, zorder=3
            ).set_data(poses[:, 0], poses[:, 1])
        for topic, xy in snap.paths.items():
            c = colour_of(index.get(topic.strip("/").split("/")[0], 0))
            style = "--" if "local" in topic else "-"
            self._line(("path", topic), color=c, lw=1.8, ls=style, zorder=4).set_data(
                xy[:, 0], xy[:, 1]
            )
        for robot, xy in snap.scans.items():
            c = _darker(colour_of(index.get(robot, 0)))
            self._line(("scan", robot), color=c, ls="none", marker="o", ms=dot, mew=0, zorder=5)
            self._artists[("scan", robot)].set_data(xy[:, 0], xy[:, 1])
        for robot, g in snap.goals.items():
            c = colour_of(index.get(robot, 0))
            self._line(
                ("goal", robot), color=c, ls="none", marker="*", ms=14, mec="black", zorder=6
            ).set_data([g[0]], [g[1]])
        for r in snap.robots:
            c = colour_of(r.index)
            self._polygon(("robot", r.name), r.outline, fc=c, ec=_darker(c), lw=1.2, zorder=7)
            reach = float(np.max(np.hypot(*(r.outline - r.pose[:2]).T))) if r.outline.size else 0.3
            x, y, yaw = r.pose
            self._line(("heading", r.name), color="black", lw=1.5, zorder=8).set_data(
                [x, x + reach * np.cos(yaw)], [y, y + reach * np.sin(yaw)]
            )
            self._text(
                ("name", r.name), x, y + reach * 1.3, r.name or "robot", ha="center",
                va="bottom", fontsize=8, zorder=9, color="black",
            )  # fmt: skip
        for key, art in self._artists.items():
            if key not in self._used:
                art.set_visible(False)
        self._time.set_text(f"t = {snap.time_s:.1f} s")
        self.fig.canvas.draw()
        rgba = np.asarray(self.fig.canvas.buffer_rgba())
        return rgba[: self.height, : self.width, :3].copy()

    def close(self) -> None:
        self.fig.clear()
