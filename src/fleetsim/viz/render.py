"""Top-down renders of a recording: the final frame as PNG, or the whole run as MP4.

``render("run.mcap", "out.png")`` draws the map, the robots with their footprints, names and
trails, their laser points, planned paths, particle clouds and goals as they were at the end
of the recording; ``render("run.mcap", "out.mp4", fps=10, speed=2)`` draws a frame every
``speed / fps`` seconds of sim time and encodes them with H.264 (imageio-ffmpeg). Long renders
show a progress bar (``progress=True``, which ``fleetsim render`` sets).

The view is the map's extent when ``/map`` was recorded, else the area the robots covered.
Only the topics a render draws are decoded, so cameras and odometry cost nothing.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fleetsim.errors import FleetsimError, RecordingError
from fleetsim.record.reader import BagMessage, BagReader
from fleetsim.viz.scene_state import SceneState
from fleetsim.viz.topdown import TopDownFigure

#: message types a render draws (a PoseStamped only on a ``.../goal`` topic)
DRAWN_TYPES = frozenset(
    {
        "tf2_msgs/msg/TFMessage",
        "sensor_msgs/msg/LaserScan",
        "nav_msgs/msg/Path",
        "geometry_msgs/msg/PoseArray",
        "geometry_msgs/msg/PolygonStamped",
        "geometry_msgs/msg/PoseStamped",
        "move_base_msgs/msg/MoveBaseActionGoal",
    }
)
#: metres of margin around the robots' area when no map was recorded
MARGIN = 1.0


@dataclass(frozen=True)
class RenderResult:
    """What was written: the file, frame count and size, and the world extent shown."""

    path: Path
    frames: int
    width: int
    height: int
    extent: tuple[float, float, float, float]

    def world_to_pixel(self, x: float, y: float) -> tuple[int, int]:
        """(column, row) of world point (x, y) in the frames; row 0 is the top."""
        xmin, xmax, ymin, ymax = self.extent
        col = (x - xmin) / (xmax - xmin) * self.width
        row = (ymax - y) / (ymax - ymin) * self.height
        return int(np.floor(col)), int(np.floor(row))


def _drawn_topics(reader: BagReader, map_topic: str) -> list[str]:
    topics = []
    for t in reader.info().topics:
        is_map = t.name == map_topic and t.typename == "nav_msgs/msg/OccupancyGrid"
        if is_map or t.typename in DRAWN_TYPES:
            topics.append(t.name)
    return topics


def _messages(reader: BagReader, topics: list[str]) -> Iterator[BagMessage]:
    return reader.messages(topics)


def _extent(state: SceneState) -> tuple[float, float, float, float]:
    b = state.bounds()
    if b is None:
        raise FleetsimError(
            f"nothing to draw: the recording has no {state.map_topic} map and no robot in tf "
            f"frame {state.fixed_frame!r}; record /tf and /map, or pass another fixed frame"
        )
    xmin, xmax, ymin, ymax = b
    if state.map is None:
        xmin, xmax, ymin, ymax = xmin - MARGIN, xmax + MARGIN, ymin - MARGIN, ymax + MARGIN
    return xmin, xmax, ymin, ymax


def _feed_all(reader: BagReader, topics: list[str], state: SceneState) -> None:
    for m in _messages(reader, topics):
        state.handle(m.topic, m.typename, m.msg, m.log_time_ns)


def render(
    path: str | Path,
    out: str | Path,
    *,
    fps: float = 10.0,
    speed: float = 1.0,
    width: int = 800,
    fixed_frame: str = "map",
    map_topic: str = "/map",
    progress: bool = False,
) -> RenderResult:
    """Render the recording ``path`` to ``out`` (``.png``: last frame; ``.mp4``: the run).

    Parameters
    ----------
    fps : video frames per second (MP4).
    speed : sim seconds per video second (MP4); 2 plays the run twice as fast.
    width : image width in pixels (the height follows the view's aspect ratio).
    fixed_frame : the tf frame the view is drawn in.
    map_topic : the OccupancyGrid drawn as background.
    progress : show a progress bar on stderr (MP4).
    """
    out = Path(out)
    suffix = out.suffix.lower()
    if suffix not in (".png", ".mp4"):
        raise FleetsimError(f"{out}: cannot render to {suffix or 'no suffix'!r}; use .png or .mp4")
    if not (fps > 0 and math.isfinite(fps)):
        raise FleetsimError(f"fps must be > 0, got {fps}")
    if not (speed > 0 and math.isfinite(speed)):
        raise FleetsimError(f"speed must be > 0 (sim seconds per video second), got {speed}")
    reader = BagReader(path)
    topics = _drawn_topics(reader, map_topic)
    params = reader.params()
    state = SceneState(fixed_frame, params, map_topic)
    _feed_all(reader, topics, state)
    extent = _extent(state)
    fig = TopDownFigure(extent, width)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise FleetsimError(f"{out}: cannot create its folder ({e.strerror})") from e
    try:
        if suffix == ".png":
            frame = fig.draw(state.snapshot())
            _write_png(out, frame)
            frames = 1
        else:
            frames = _render_mp4(reader, topics, fig, out, fps, speed, progress, state)
    finally:
        fig.close()
    return RenderResult(out, frames, fig.width, fig.height, fig.extent)


def _write_png(out: Path, frame: np.ndarray) -> None:
    import imageio.v3 as iio

    try:
        iio.imwrite(out, frame)
    except OSError as e:
        raise FleetsimError(f"{out}: cannot write ({e})") from e


def frame_times_ns(start_ns: int, end_ns: int, fps: float, speed: float) -> np.ndarray:
    """Sim times (ns, int64) of the video frames: every ``speed / fps`` s from start to end."""
    step = speed / fps * 1e9
    n = math.floor((end_ns - start_ns) / step + 1e-9) + 1
    return start_ns + np.round(np.arange(n) * step).astype(np.int64)


def _render_mp4(
    reader: BagReader,
    topics: list[str],
    fig: TopDownFigure,
    out: Path,
    fps: float,
    speed: float,
    progress: bool,
    final: SceneState,
) -> int:
    import imageio.v2 as imageio

    info = reader.info()
    times = frame_times_ns(info.start_ns, info.end_ns, fps, speed)
    state = SceneState(final.fixed_frame, final.params, final.map_topic)
    messages = _messages(reader, topics)
    pending = next(messages, None)
    try:
        writer = imageio.get_writer(
            str(out), format="FFMPEG", mode="I", fps=fps, codec="libx264",
            pixelformat="yuv420p", macro_block_size=1, ffmpeg_log_level="error",
        )  # fmt: skip
    except Exception as e:  # imageio raises plain exceptions for ffmpeg problems
        raise RecordingError(f"{out}: cannot open the video writer ({e})") from e
    bar = _progress(progress, len(times), out)
    try:
        for t in times:
            while pending is not None and pending.log_time_ns <= t:
                state.handle(pending.topic, pending.typename, pending.msg, pending.log_time_ns)
                pending = next(messages, None)
            state.time_ns = max(state.time_ns, int(t))
            writer.append_data(fig.draw(state.snapshot()))
            if bar is not None:
                bar[0].advance(bar[1])
    finally:
        writer.close()
        if bar is not None:
            bar[0].stop()
    return len(times)


def _progress(enabled: bool, total: int, out: Path):
    if not enabled:
        return None
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeRemainingColumn

    bar = Progress(
        "[progress.description]{task.description}",
        BarColumn(),
        MofNCompleteColumn(),
        TimeRemainingColumn(),
        console=Console(stderr=True),
    )
    task = bar.add_task(f"rendering {out.name}", total=total)
    bar.start()
    return bar, task
