"""map_server's map loading and map_saver's writing, as arrays.

`load_map` reads a map YAML (``image``, ``resolution``, ``origin``, ``negate``,
``occupied_thresh``, ``free_thresh``, optional ``mode``: trinary / scale / raw) and its PGM/PNG
image exactly as map_server's ``image_loader`` does; `load_map_image` is the legacy
``map_server IMAGE RESOLUTION`` form. `save_map` writes PGM + YAML as ``map_saver`` does.

Grid convention (nav_msgs/OccupancyGrid): ``data[row, col]`` with row 0 at the map origin's y,
so image row 0 (the top of the picture) becomes the last data row. Values are int8: 0 free,
100 occupied, -1 unknown, 1..99 scaled occupancy (mode scale), raw pixel values (mode raw).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml
from PIL import Image

from fleetsim.nav.errors import MapError

MODES = ("trinary", "scale", "raw")
_REQUIRED = ("image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh")


@dataclass(frozen=True)
class OccupancyMap:
    """An occupancy grid as arrays (the payload of nav_msgs/OccupancyGrid).

    data : (height, width) int8, row 0 at ``origin`` y, column 0 at ``origin`` x.
    resolution : metres per cell.
    origin : (x, y, yaw) of cell (0, 0)'s lower-left corner in the map frame, m and rad.
    """

    data: np.ndarray
    resolution: float
    origin: tuple[float, float, float]

    @property
    def width(self) -> int:
        return int(self.data.shape[1])

    @property
    def height(self) -> int:
        return int(self.data.shape[0])


def occupancy_from_pixels(
    pixels: np.ndarray,
    *,
    negate: bool,
    occupied_thresh: float,
    free_thresh: float,
    mode: str = "trinary",
) -> np.ndarray:
    """Occupancy values of an image, as map_server's image_loader computes them.

    Parameters
    ----------
    pixels : (rows, cols) or (rows, cols, channels) uint8 image, row 0 the top of the picture.
        With 2 or 4 channels the last is alpha; alpha is averaged with the colours in trinary
        mode (as map_server does) and left out of the average otherwise.
    negate, occupied_thresh, free_thresh, mode : the map YAML fields.

    Returns
    -------
    (rows, cols) int8 with row 0 at the bottom of the picture (the map origin).
    """
    if mode not in MODES:
        raise MapError(f"map mode '{mode}' is not one of {', '.join(MODES)}")
    img = np.asarray(pixels)
    if img.ndim == 2:
        img = img[:, :, None]
    n = img.shape[2]
    has_alpha = n in (2, 4)
    avg_n = n if (mode == "trinary" or not has_alpha) else n - 1
    color_avg = img[:, :, :avg_n].astype(np.float64).sum(axis=2) / avg_n
    alpha = img[:, :, n - 1].astype(np.float64) if n > 1 else np.full(color_avg.shape, 1.0)
    if negate:
        color_avg = 255.0 - color_avg
    if mode == "raw":
        value = color_avg.astype(np.int64).astype(np.uint8).view(np.int8)
        return np.ascontiguousarray(value[::-1])
    occ = (255.0 - color_avg) / 255.0
    value = np.full(occ.shape, -1, dtype=np.int8)
    if mode == "scale":
        ratio = (occ - free_thresh) / (occ_range := (occupied_thresh - free_thresh))
        scaled = (1.0 + 98.0 * ratio).astype(np.int64) if occ_range > 0 else np.zeros(occ.shape)
        middle = alpha >= 1.0
        value[middle] = scaled[middle].astype(np.int8)
    value[occ > occupied_thresh] = 100
    value[occ < free_thresh] = 0
    return np.ascontiguousarray(value[::-1])


def _read_pixels(image_path: Path, where: str) -> np.ndarray:
    try:
        with Image.open(image_path) as im:
            if im.mode in ("I", "I;16", "F"):
                raise MapError(
                    f"{where}: image {image_path} has {im.mode} pixels; map_server reads 8-bit "
                    "grey or RGB(A) images"
                )
            if im.mode == "P":
                im = im.convert("RGBA" if "transparency" in im.info else "RGB")
            if im.mode not in ("L", "LA", "RGB", "RGBA"):
                im = im.convert("RGB")
            return np.asarray(im, dtype=np.uint8)
    except FileNotFoundError:
        raise MapError(f"{where}: map image {image_path} does not exist") from None
    except OSError as e:
        raise MapError(f"{where}: cannot read map image {image_path}: {e}") from None


def load_map_image(
    image: str | Path,
    resolution: float,
    *,
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0),
    negate: bool = False,
    occupied_thresh: float = 0.65,
    free_thresh: float = 0.196,
    mode: str = "trinary",
) -> OccupancyMap:
    """The legacy ``map_server IMAGE RESOLUTION`` form (and the worker behind `load_map`)."""
    where = str(image)
    _check_resolution(resolution, where)
    if not 0.0 <= free_thresh <= occupied_thresh <= 1.0:
        raise MapError(
            f"{where}: need 0 <= free_thresh <= occupied_thresh <= 1, got free_thresh "
            f"{free_thresh} and occupied_thresh {occupied_thresh}"
        )
    pixels = _read_pixels(Path(image), where)
    data = occupancy_from_pixels(
        pixels,
        negate=negate,
        occupied_thresh=occupied_thresh,
        free_thresh=free_thresh,
        mode=mode,
    )
    ox, oy, oyaw = (float(v) for v in origin)
    return OccupancyMap(data=data, resolution=float(resolution), origin=(ox, oy, oyaw))


def _check_resolution(resolution: object, where: str) -> None:
    if (
        isinstance(resolution, bool)
        or not isinstance(resolution, int | float)
        or not math.isfinite(resolution)
        or resolution <= 0
    ):
        raise MapError(f"{where}: resolution must be a positive number, got {resolution!r}")


def load_map(yaml_path: str | Path) -> OccupancyMap:
    """Load a map YAML and its image as map_server does (image path relative to the YAML)."""
    path = Path(yaml_path)
    if path.suffix.lower() in (".world", ".sdf", ".xml", ".launch", ".urdf", ".xacro"):
        raise MapError(
            f"{path}: map_server needs a map YAML (image, resolution, origin, ...), not a "
            f"{path.suffix} file; a Gazebo world has no map: make one with gmapping and "
            "map_saver, or give the map the world was made from"
        )
    try:
        doc = yaml.safe_load(path.read_text())
    except FileNotFoundError:
        raise MapError(f"map file {path} does not exist") from None
    except yaml.YAMLError as e:
        raise MapError(f"{path}: the map YAML does not parse: {e}") from None
    if not isinstance(doc, dict):
        raise MapError(f"{path}: a map YAML must be a mapping with the fields {_REQUIRED}")
    for key in _REQUIRED:
        if key not in doc:
            raise MapError(f"{path}: the map does not contain a '{key}' field")
    mode = doc.get("mode", "trinary")
    if mode not in MODES:
        raise MapError(f"{path}: field 'mode' is '{mode}', expected trinary, scale or raw")
    origin = doc["origin"]
    if (
        not isinstance(origin, list | tuple)
        or len(origin) != 3
        or not all(isinstance(v, int | float) and not isinstance(v, bool) for v in origin)
    ):
        raise MapError(f"{path}: field 'origin' must be [x, y, yaw], got {origin!r}")
    for key in ("occupied_thresh", "free_thresh"):
        v = doc[key]
        if isinstance(v, bool) or not isinstance(v, int | float):
            raise MapError(f"{path}: field '{key}' must be a number, got {v!r}")
    negate = doc["negate"]
    if isinstance(negate, bool) or negate in (0, 1):
        negate = bool(negate)
    else:
        raise MapError(f"{path}: field 'negate' must be 0 or 1, got {negate!r}")
    _check_resolution(doc["resolution"], f"{path}: field 'resolution'")
    image = Path(str(doc["image"]))
    if not image.is_absolute():
        image = path.parent / image
    try:
        return load_map_image(
            image,
            doc["resolution"],
            origin=tuple(origin),
            negate=negate,
            occupied_thresh=float(doc["occupied_thresh"]),
            free_thresh=float(doc["free_thresh"]),
            mode=mode,
        )
    except MapError as e:
        raise MapError(f"{path}: {e}") from None


def pixels_from_occupancy(
    data: np.ndarray, occupied_threshold: int = 65, free_threshold: int = 25
) -> np.ndarray:
    """map_saver's picture of a grid: free 254, occupied 0, unknown 205; row 0 the top.

    A cell is free when ``0 <= value <= free_threshold``, occupied when ``value >=
    occupied_threshold``, and unknown otherwise (map_saver's ``--free`` / ``--occ``).
    """
    d = np.asarray(data).astype(np.int16)
    out = np.full(d.shape, 205, dtype=np.uint8)
    out[(d >= 0) & (d <= free_threshold)] = 254
    out[d >= occupied_threshold] = 0
    return np.ascontiguousarray(out[::-1])


def save_map(
    occupancy: OccupancyMap,
    map_name: str | Path,
    *,
    occupied_threshold: int = 65,
    free_threshold: int = 25,
) -> tuple[Path, Path]:
    """Write ``<map_name>.pgm`` and ``<map_name>.yaml`` as map_saver does; returns both paths."""
    if occupancy.data.ndim != 2 or occupancy.data.size == 0:
        raise MapError(f"cannot save map {map_name}: data must be a non-empty 2-D grid")
    if not 0 <= free_threshold < occupied_threshold <= 100:
        raise MapError(
            f"cannot save map {map_name}: need 0 <= free ({free_threshold}) < occ "
            f"({occupied_threshold}) <= 100"
        )
    base = Path(map_name)
    pgm, yml = base.with_name(base.name + ".pgm"), base.with_name(base.name + ".yaml")
    pixels = pixels_from_occupancy(occupancy.data, occupied_threshold, free_threshold)
    header = (
        f"P5\n# CREATOR: map_saver.cpp {occupancy.resolution:.3f} m/pix\n"
        f"{occupancy.width} {occupancy.height}\n255\n"
    ).encode()
    ox, oy, oyaw = occupancy.origin
    text = (
        f"image: {pgm.name}\nresolution: {occupancy.resolution:f}\n"
        f"origin: [{ox:f}, {oy:f}, {oyaw:f}]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n\n"
    )
    try:
        pgm.write_bytes(header + pixels.tobytes())
        yml.write_text(text)
    except OSError as e:
        raise MapError(f"cannot write map {base}: {e.strerror}") from None
    return pgm, yml
