"""Vision failures, all `FleetsimError` subclasses."""

from __future__ import annotations

from fleetsim.errors import FleetsimError


class VisionError(FleetsimError):
    """An image or calibration a vision node cannot use (encoding, camera_info, JPEG)."""
