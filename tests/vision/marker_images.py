"""Synthetic camera images of an ArUco marker at a known pose (until rendered ones exist).

The marker is drawn as the tutorial's texture is made (DICT_4X4_50, the black border reaching
the texture's edge, no white margin), warped by the homography that a pinhole camera with
matrix K gives for the marker's pose, on a grey background, 4x supersampled then averaged down
(as a renderer's anti-aliasing would), so edges fall between pixels.
"""

from __future__ import annotations

import cv2
import numpy as np

from fleetsim.msgs import sensor_msgs, std_msgs
from fleetsim.msgs.builtin_interfaces import Time

SUPERSAMPLE = 4


def camera_matrix(width: int, height: int, hfov: float) -> np.ndarray:
    """K of a Gazebo camera of that size and horizontal field of view (rad)."""
    f = (width / 2) / np.tan(hfov / 2)
    return np.array([[f, 0, (width + 1) / 2], [0, f, (height + 1) / 2], [0, 0, 1.0]])


def marker_texture(marker_id: int = 0, px: int = 600) -> np.ndarray:
    d = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_50)
    return cv2.aruco.generateImageMarker(d, marker_id, px)


def marker_image(
    rvec, tvec, K: np.ndarray, width: int, height: int, length: float = 0.15,
    marker_id: int = 0, background: int = 170, noise: float = 0.0, rng=None,
) -> np.ndarray:  # fmt: skip
    """(H, W, 3) uint8 RGB: the marker of side ``length`` m at pose (rvec, tvec) in the optical
    frame (x right, y down, z forward; marker frame x right, y up, z out of its face)."""
    s = SUPERSAMPLE
    tex = marker_texture(marker_id)
    n = tex.shape[0]
    h = length / 2
    obj = np.array([[-h, h, 0], [h, h, 0], [h, -h, 0], [-h, -h, 0]], dtype=np.float64)
    Ks = K.copy()
    Ks[:2] *= s
    Ks[:2, 2] = K[:2, 2] * s + (s - 1) / 2  # small pixel i is big pixels s*i .. s*i+s-1
    img_pts, _ = cv2.projectPoints(obj, np.asarray(rvec, float), np.asarray(tvec, float), Ks, None)
    src = np.array([[0, 0], [n, 0], [n, n], [0, n]], dtype=np.float32) - 0.5
    H = cv2.getPerspectiveTransform(src, img_pts.reshape(4, 2).astype(np.float32))
    big = np.full((height * s, width * s), background, np.uint8)
    mask = np.full_like(tex, 255)
    warped = cv2.warpPerspective(tex, H, (width * s, height * s), flags=cv2.INTER_LINEAR)
    inside = cv2.warpPerspective(mask, H, (width * s, height * s), flags=cv2.INTER_NEAREST)
    big[inside > 0] = warped[inside > 0]
    img = cv2.resize(big, (width, height), interpolation=cv2.INTER_AREA).astype(np.float64)
    if noise and rng is not None:
        img += rng.normal(0, noise, img.shape)
    gray = np.clip(np.round(img), 0, 255).astype(np.uint8)
    return np.repeat(gray[..., None], 3, axis=2)


def image_msg(rgb: np.ndarray, t: float = 0.0, frame: str = "camera_rgb_optical_frame"):
    h, w = rgb.shape[:2]
    return sensor_msgs.Image(
        header=std_msgs.Header(stamp=Time.from_sec(t), frame_id=frame),
        height=h, width=w, encoding="rgb8", step=w * 3, data=rgb.reshape(-1),
    )  # fmt: skip


def camera_info_msg(K: np.ndarray, width: int, height: int, frame="camera_rgb_optical_frame"):
    P = np.zeros((3, 4))
    P[:, :3] = K
    return sensor_msgs.CameraInfo(
        header=std_msgs.Header(frame_id=frame),
        height=height, width=width, distortion_model="plumb_bob", d=np.zeros(5),
        k=K.reshape(-1), r=np.eye(3).reshape(-1), p=P.reshape(-1),
    )  # fmt: skip
