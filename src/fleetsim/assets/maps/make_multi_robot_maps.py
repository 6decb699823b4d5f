"""Draw the worlds of the multi-robot avoidance scenarios (PGM + YAML, 0.05 m per cell).

* ``corridor``: a corridor 12 m long and 2 m wide (free space x 1..13, y 1..3 in the map
  frame), closed at both ends, inside a 14 x 4 m map; ``swap_corridor`` sends robots from one
  end to the other;
* ``corridor_narrow``: the same corridor narrowed to 1.0 m (y 1.5..2.5) for its middle 6 m
  (x 4..10), 2 m wide for 3 m at each end: ``swap_corridor width:=1.0``, where two lizis cannot
  pass each other in the narrow part and one has to back out into a wide end;
* ``open_room``: a walled 14 x 14 m room with nothing in it; ``circle`` puts the robots on a
  circle of 6 m diameter around its centre (7, 7).

Run ``python make_multi_robot_maps.py [OUTDIR]`` to rewrite them (deterministic).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

RES = 0.05  # m per cell
WALL = 0.15  # m
FREE, OCCUPIED = 254, 0


def _cells(v: float) -> int:
    return round(v / RES)


def _box(img: np.ndarray, x0: float, y0: float, x1: float, y1: float) -> None:
    """Fill [x0, x1] x [y0, y1] (metres, y up) as occupied."""
    h = img.shape[0]
    c0, c1 = _cells(x0), _cells(x1)
    r0, r1 = h - _cells(y1), h - _cells(y0)
    img[max(r0, 0) : r1, max(c0, 0) : c1] = OCCUPIED


def walled(width: float, height: float, inner: tuple[float, float, float, float]) -> np.ndarray:
    """A map ``width`` x ``height`` m, occupied except the free box ``inner`` (x0, y0, x1, y1)
    whose walls are WALL thick; row 0 at the top, as map_server reads it."""
    img = np.full((_cells(height), _cells(width)), FREE, np.uint8)
    x0, y0, x1, y1 = inner
    _box(img, x0 - WALL, y0 - WALL, x1 + WALL, y0)
    _box(img, x0 - WALL, y1, x1 + WALL, y1 + WALL)
    _box(img, x0 - WALL, y0 - WALL, x0, y1 + WALL)
    _box(img, x1, y0 - WALL, x1 + WALL, y1 + WALL)
    return img


def narrowed(img: np.ndarray, x0: float, x1: float, y0: float, y1: float, width: float):
    """Narrow the free band y0..y1 to ``width`` m around its centre for x0..x1."""
    mid = (y0 + y1) / 2.0
    _box(img, x0, y0, x1, mid - width / 2.0)
    _box(img, x0, mid + width / 2.0, x1, y1)
    return img


MAPS = {
    "corridor": (14.0, 4.0, (1.0, 1.0, 13.0, 3.0), "a 12 x 2 m corridor"),
    "corridor_narrow": (
        14.0,
        4.0,
        (1.0, 1.0, 13.0, 3.0),
        "a 12 x 2 m corridor, 1.0 m wide for x 4..10",
    ),
    "open_room": (14.0, 14.0, (0.5, 0.5, 13.5, 13.5), "an empty 13 x 13 m room"),
}
#: narrowed parts (x0, x1, width) of the maps that have one
NARROW = {"corridor_narrow": (4.0, 10.0, 1.0)}


def write(outdir: Path) -> list[Path]:
    out = []
    for name, (w, h, inner, what) in MAPS.items():
        img = walled(w, h, inner)
        if name in NARROW:
            x0, x1, width = NARROW[name]
            narrowed(img, x0, x1, inner[1], inner[3], width)
        pgm = outdir / f"{name}.pgm"
        with pgm.open("wb") as f:
            head = f"P5\n# fleetsim {what}, {RES} m/cell\n{img.shape[1]} {img.shape[0]}\n255\n"
            f.write(head.encode())
            f.write(img.tobytes())
        yml = outdir / f"{name}.yaml"
        yml.write_text(
            f"# fleetsim {what} ({w:g} x {h:g} m map), drawn by make_multi_robot_maps.py\n"
            f"image: {name}.pgm\nresolution: {RES}\norigin: [0.0, 0.0, 0.0]\n"
            "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
        )
        out += [pgm, yml]
    return out


if __name__ == "__main__":
    target = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parent
    for p in write(target):
        print(p)
