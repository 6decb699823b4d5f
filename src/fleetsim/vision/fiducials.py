"""ArUco detection and marker pose as aruco_detect computes them, as pure functions.

Detection is OpenCV's ArUco module (`cv2.aruco.ArucoDetector`); pose is one `cv2.solvePnP` per
marker on the four corners of a square of side L centred on the marker, x right, y up, z out of
the face toward the camera: ``(-L/2, L/2, 0), (L/2, L/2, 0), (L/2, -L/2, 0), (-L/2, -L/2, 0)``
(aruco_detect's ``getSingleMarkerObjectPoints``), corners in OpenCV order (top-left, top-right,
bottom-right, bottom-left).

The fiducials package calls ``solvePnP`` with its default (iterative) method; we use
``SOLVEPNP_IPPE_SQUARE``'s two solutions (OpenCV's solver made for exactly these four points,
one per ambiguity basin) beside the package's iterative one, and polish the one that
reprojects best by Levenberg-Marquardt (see `_best_pose` for why one solver is not enough).

``image_error`` is the mean of the squared corner reprojection errors in px^2 (the package's
comment says RMS, but it takes no root); ``object_error`` converts it to metres as the package
does: ``image_error / |c0 - c2| * |t| / fiducial_len``; ``fiducial_area`` is the quad's pixel area
by Heron's formula over the triangles (c0, c1, c3) and (c1, c2, c3).
"""

from __future__ import annotations

import re

import cv2
import numpy as np
from scipy.spatial.transform import Rotation

from fleetsim.errors import ParameterError

#: aruco_detect's ``dictionary`` integer -> OpenCV's predefined dictionary (ROS wiki order)
DICTIONARIES: tuple[str, ...] = (
    "DICT_4X4_50",
    "DICT_4X4_100",
    "DICT_4X4_250",
    "DICT_4X4_1000",
    "DICT_5X5_50",
    "DICT_5X5_100",
    "DICT_5X5_250",
    "DICT_5X5_1000",
    "DICT_6X6_50",
    "DICT_6X6_100",
    "DICT_6X6_250",
    "DICT_6X6_1000",
    "DICT_7X7_50",
    "DICT_7X7_100",
    "DICT_7X7_250",
    "DICT_7X7_1000",
    "DICT_ARUCO_ORIGINAL",
)


def aruco_dictionary(index: int, where: str = "dictionary") -> cv2.aruco.Dictionary:
    """OpenCV's predefined dictionary for aruco_detect's ``dictionary`` number (0..16)."""
    if isinstance(index, bool) or not isinstance(index, int) or not 0 <= index < len(DICTIONARIES):
        listing = ", ".join(f"{i} {n}" for i, n in enumerate(DICTIONARIES))
        raise ParameterError(f"{where}: unknown ArUco dictionary {index!r}; known: {listing}")
    return cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, DICTIONARIES[index]))


def dictionary_size(index: int) -> int:
    """How many marker ids dictionary ``index`` holds."""
    return int(aruco_dictionary(index).bytesList.shape[0])


_ID = r"\s*(\d+)\s*"
_RANGE = re.compile(rf"^{_ID}(?:-{_ID})?$")


def _ids(part: str, size: int, where: str, text: str) -> range:
    m = _RANGE.match(part)
    if m is None:
        raise ParameterError(
            f"{where}: cannot read '{part.strip()}' in {text!r}: write ids and ranges as '1,4,9-12'"
        )
    lo = int(m.group(1))
    hi = int(m.group(2)) if m.group(2) is not None else lo
    if hi < lo:
        raise ParameterError(f"{where}: range '{part.strip()}' in {text!r} runs backwards")
    if hi >= size:
        raise ParameterError(
            f"{where}: id {hi} in {text!r} is not in the dictionary, whose ids are 0..{size - 1}"
        )
    return range(lo, hi + 1)


def parse_id_list(text: str, size: int, where: str = "ignore_fiducials") -> frozenset[int]:
    """Ids from aruco_detect's list syntax (``"1,4,8,9-12"``); ``size``: the dictionary's."""
    out: set[int] = set()
    for part in text.split(","):
        if part.strip():
            out.update(_ids(part, size, where, text))
    return frozenset(out)


def parse_len_override(
    text: str, size: int, where: str = "fiducial_len_override"
) -> dict[int, float]:
    """Per-id side lengths from ``"1-10: 0.05, 12: 0.06"`` (ids or ranges, then metres)."""
    out: dict[int, float] = {}
    for part in text.split(","):
        if not part.strip():
            continue
        ids, sep, length = part.partition(":")
        try:
            value = float(length) if sep else float("nan")
        except ValueError:
            value = float("nan")
        if not value > 0 or not np.isfinite(value):
            raise ParameterError(
                f"{where}: cannot read '{part.strip()}' in {text!r}: write 'id: length' or "
                "'first-last: length' with a positive length in metres"
            )
        for i in _ids(ids, size, where, text):
            out[i] = value
    return out


def marker_object_points(length: float) -> np.ndarray:
    """(4, 3) float64 corners of a marker of side ``length`` m in its own frame (m)."""
    h = length / 2.0
    return np.array([[-h, h, 0.0], [h, h, 0.0], [h, -h, 0.0], [-h, -h, 0.0]])


def marker_poses(
    corners: np.ndarray, lengths: np.ndarray, camera_matrix: np.ndarray, dist_coeffs: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pose of each marker in the camera's optical frame by solvePnP.

    Parameters
    ----------
    corners : (N, 4, 2) float, pixels, OpenCV corner order.
    lengths : (N,) float, each marker's side in m.
    camera_matrix : (3, 3) K; dist_coeffs : (5,) plumb-bob D.

    Returns
    -------
    rvecs : (N, 3) axis-angle (rad), tvecs : (N, 3) m, image_errors : (N,) mean squared
    corner reprojection error in px^2.
    """
    n = len(corners)
    rvecs, tvecs, errors = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n)
    for i in range(n):
        obj = marker_object_points(float(lengths[i]))
        img = np.asarray(corners[i], dtype=np.float64).reshape(4, 2)
        best = _best_pose(obj, img, camera_matrix, dist_coeffs)
        errors[i] = best[0]  # inf: neither method solved it; the caller reports it unseen
        if best[1] is not None:
            rvecs[i], tvecs[i] = best[1].ravel(), best[2].ravel()
    return rvecs, tvecs, errors


def _reprojection_error(obj, img, rvec, tvec, camera_matrix, dist_coeffs) -> float:
    proj, _ = cv2.projectPoints(obj, rvec, tvec, camera_matrix, dist_coeffs)
    return float(np.mean(np.sum((proj.reshape(4, 2) - img) ** 2, axis=1)))


#: the LM polish runs to machine precision (its default, 20 steps to float32's epsilon, leaves
#: face-on poses milliradians off)
_LM_CRITERIA = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_COUNT, 200, 1e-15)


def _best_pose(obj, img, camera_matrix, dist_coeffs):
    """(error px^2, rvec, tvec) of the pose that reprojects best, or (inf, None, None).

    Candidates are both IPPE_SQUARE solutions (one per ambiguity basin) and the iterative
    solver's (the package's method); the best of them is polished by Levenberg-Marquardt. One
    solver is not enough: near fronto-parallel OpenCV's IPPE_SQUARE can answer tenths of a
    radian off with a sub-0.1 px error, or NaN, and in oblique close views pixels off; the
    iterative solver can stop short of the minimum. Poses behind the camera (the mirror image,
    which projects the same) and non-finite ones are dropped.
    """
    n, rvecs, tvecs, _ = cv2.solvePnPGeneric(
        obj, img, camera_matrix, dist_coeffs, flags=cv2.SOLVEPNP_IPPE_SQUARE
    )
    seeds = [(rvecs[k], tvecs[k]) for k in range(n)]
    ok, rvec, tvec = cv2.solvePnP(
        obj, img, camera_matrix, dist_coeffs, flags=cv2.SOLVEPNP_ITERATIVE
    )
    if ok:
        seeds.append((rvec, tvec))
    best = (np.inf, None, None)
    for rvec, tvec in seeds:
        if _in_front(rvec, tvec):
            err = _reprojection_error(obj, img, rvec, tvec, camera_matrix, dist_coeffs)
            if err < best[0]:
                best = (err, rvec, tvec)
    if best[1] is not None:
        rvec, tvec = cv2.solvePnPRefineLM(
            obj, img, camera_matrix, dist_coeffs, best[1].copy(), best[2].copy(), _LM_CRITERIA
        )
        if _in_front(rvec, tvec):
            err = _reprojection_error(obj, img, rvec, tvec, camera_matrix, dist_coeffs)
            if err <= best[0]:
                best = (err, rvec, tvec)
    return best


def _in_front(rvec: np.ndarray, tvec: np.ndarray) -> bool:
    return bool(np.all(np.isfinite(rvec)) and np.all(np.isfinite(tvec)) and tvec.ravel()[2] > 0)


def object_errors(
    image_errors: np.ndarray, corners: np.ndarray, tvecs: np.ndarray, fiducial_len: float
) -> np.ndarray:
    """(N,) aruco_detect's ``object_error``: image error scaled to metres (see module doc)."""
    corners = np.asarray(corners, dtype=np.float64).reshape(-1, 4, 2)
    diag = np.linalg.norm(corners[:, 0] - corners[:, 2], axis=1)
    return image_errors / diag * np.linalg.norm(tvecs, axis=1) / fiducial_len


def _heron(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    s = (a + b + c) / 2.0
    return np.sqrt(np.maximum(s * (s - a) * (s - b) * (s - c), 0.0))


def fiducial_areas(corners: np.ndarray) -> np.ndarray:
    """(N,) pixel area of each (N, 4, 2) quad, as aruco_detect's ``calcFiducialArea``."""
    c = np.asarray(corners, dtype=np.float64).reshape(-1, 4, 2)
    d = lambda i, j: np.linalg.norm(c[:, i] - c[:, j], axis=1)  # noqa: E731
    diag = d(1, 3)
    return _heron(d(0, 1), d(0, 3), diag) + _heron(d(1, 2), d(2, 3), diag)


def quaternions_from_rotvecs(rvecs: np.ndarray) -> np.ndarray:
    """(N, 4) unit quaternions (x, y, z, w) of (N, 3) axis-angle vectors (rad)."""
    rvecs = np.asarray(rvecs, dtype=np.float64).reshape(-1, 3)
    if len(rvecs) == 0:
        return np.zeros((0, 4))
    return Rotation.from_rotvec(rvecs).as_quat()
