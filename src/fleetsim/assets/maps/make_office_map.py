"""Draw fleetsim's demo office floor: a 30 x 20 m map at 0.05 m per cell (PGM + YAML).

Layout (metres, map frame = world frame, origin at the lower-left corner): outer walls; a
3 m wide east-west corridor (y 8.5 to 11.5); five 6 m offices south of it and three 10 m
rooms north of it, each with a door onto the corridor; desks in some rooms and two pillars in
the northern rooms. Run ``python make_office_map.py [OUTDIR]`` to rewrite ``office.pgm`` and
``office.yaml`` (deterministic).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

RES = 0.05  # m per cell
WIDTH, HEIGHT = 30.0, 20.0  # m
WALL = 0.15  # m
FREE, OCCUPIED = 254, 0


def _cells(v: float) -> int:
    return round(v / RES)


def _box(img: np.ndarray, x0: float, y0: float, x1: float, y1: float) -> None:
    """Fill the rectangle [x0, x1] x [y0, y1] (metres, y up) as occupied."""
    h = img.shape[0]
    c0, c1 = _cells(min(x0, x1)), _cells(max(x0, x1))
    r0, r1 = h - _cells(max(y0, y1)), h - _cells(min(y0, y1))
    img[max(r0, 0) : max(r1, r0 + 1), max(c0, 0) : max(c1, c0 + 1)] = OCCUPIED


def _hwall(img, y, x0, x1, doors=()):
    """A horizontal wall at height y from x0 to x1 with door gaps (centre, width)."""
    xs = [x0]
    for centre, width in sorted(doors):
        xs += [centre - width / 2, centre + width / 2]
    xs.append(x1)
    for a, b in zip(xs[::2], xs[1::2]):
        _box(img, a, y - WALL / 2, b, y + WALL / 2)


def _vwall(img, x, y0, y1):
    _box(img, x - WALL / 2, y0, x + WALL / 2, y1)


def office_image() -> np.ndarray:
    """The map as a (400, 600) uint8 image, row 0 at the top (as map_server reads it)."""
    img = np.full((_cells(HEIGHT), _cells(WIDTH)), FREE, np.uint8)
    # outer walls
    _box(img, 0, 0, WIDTH, WALL)
    _box(img, 0, HEIGHT - WALL, WIDTH, HEIGHT)
    _box(img, 0, 0, WALL, HEIGHT)
    _box(img, WIDTH - WALL, 0, WIDTH, HEIGHT)
    # corridor walls with doors: five offices to the south, three rooms to the north
    _hwall(img, 8.5, 0, WIDTH, doors=[(3.0 + 6.0 * i, 1.0) for i in range(5)])
    _hwall(img, 11.5, 0, WIDTH, doors=[(5.0, 1.2), (15.0, 1.2), (25.0, 1.2)])
    for x in (6.0, 12.0, 18.0, 24.0):
        _vwall(img, x, 0, 8.5)
    for x in (10.0, 20.0):
        _vwall(img, x, 11.5, HEIGHT)
    # furniture: a desk in each office, a meeting table and two pillars in the north rooms
    for i in range(5):
        _box(img, 1.2 + 6.0 * i, 1.0, 2.8 + 6.0 * i, 1.8)
    _box(img, 13.5, 14.5, 16.5, 16.0)
    _box(img, 4.0, 15.5, 4.4, 15.9)
    _box(img, 25.6, 15.5, 26.0, 15.9)
    return img


def write(outdir: Path) -> tuple[Path, Path]:
    """Write ``office.pgm`` (binary P5) and ``office.yaml`` into ``outdir``."""
    img = office_image()
    pgm = outdir / "office.pgm"
    with pgm.open("wb") as f:
        header = f"P5\n# fleetsim demo office, {RES} m/cell\n{img.shape[1]} {img.shape[0]}\n255\n"
        f.write(header.encode())
        f.write(img.tobytes())
    yml = outdir / "office.yaml"
    yml.write_text(
        "# fleetsim demo office floor (30 x 20 m), drawn by make_office_map.py\n"
        f"image: office.pgm\nresolution: {RES}\norigin: [0.0, 0.0, 0.0]\n"
        "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    return pgm, yml


if __name__ == "__main__":
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parent
    for p in write(out):
        print(p)
