"""Draw the texture of fleetsim's ``aruco_marker`` model with OpenCV's ArUco module.

The marker is ``DICT_4X4_50`` id 0, as the tutorial's (grobot's ``marker.png``): 4 x 4 data
bits inside a one-cell black border, 6 x 6 cells in all. Unlike the tutorial's image, which
stops at the black border, a one-cell white margin surrounds it, as on a printed marker: the
detector needs the contrast at the border, and the marker is seen against robots and walls of
any colour. The model's face is therefore 8 cells across; with the marker's black square at
0.15 m (aruco_detect's ``fiducial_len``) a cell is 0.025 m and the face 0.20 m.

Run ``python make_aruco_marker.py [OUTFILE]`` to rewrite
``models/aruco_marker/materials/textures/marker.png`` (deterministic).
"""

from __future__ import annotations

import sys
from pathlib import Path

import cv2
import numpy as np

DICTIONARY = cv2.aruco.DICT_4X4_50
MARKER_ID = 0
CELL_PX = 64  # pixels per marker cell
CELLS = 6  # 4 data bits + 2 border cells
MARGIN_CELLS = 1  # white quiet zone around the black border, per side
MARKER_SIDE = 0.15  # m, the black square (aruco_detect's fiducial_len)
FACE_SIDE = MARKER_SIDE * (CELLS + 2 * MARGIN_CELLS) / CELLS  # m, the model's face: 0.20

OUT = Path(__file__).resolve().parent / "models/aruco_marker/materials/textures/marker.png"


def marker_image() -> np.ndarray:
    """The texture: (512, 512) uint8 grey levels, marker centred in its white margin."""
    dictionary = cv2.aruco.getPredefinedDictionary(DICTIONARY)
    marker = cv2.aruco.generateImageMarker(dictionary, MARKER_ID, CELLS * CELL_PX, borderBits=1)
    pad = MARGIN_CELLS * CELL_PX
    return np.pad(marker, pad, constant_values=255)


def main(out: Path = OUT) -> None:
    out.parent.mkdir(parents=True, exist_ok=True)
    if not cv2.imwrite(str(out), marker_image()):
        raise SystemExit(f"cannot write {out}")
    print(f"wrote {out} ({FACE_SIDE:.3f} m face, {MARKER_SIDE} m marker)")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else OUT)
