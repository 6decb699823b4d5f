"""``static_transform_publisher``: the node from ROS's ``tf`` and ``tf2_ros`` packages.

Argument forms (``args=`` of a launch ``<node>``)::

    x y z yaw pitch roll frame_id child_frame_id period_in_ms     tf: /tf every period
    x y z qx qy qz qw frame_id child_frame_id period_in_ms        tf: /tf every period
    x y z yaw pitch roll frame_id child_frame_id                  tf2_ros: latched /tf_static
    x y z qx qy qz qw frame_id child_frame_id                     tf2_ros: latched /tf_static
    --x X --y Y --z Z --yaw Y --pitch P --roll R (or --qx --qy --qz --qw)
        --frame-id F --child-frame-id C                           ROS 2 tf2_ros flags

Translations are metres, angles radians: yaw about z, pitch about y, roll about x
(``R = Rz(yaw) Ry(pitch) Rx(roll)``). Like ROS's tf, the periodic form stamps each transform
one period in the future, so that lookups at the current time succeed between publications.
Frame ids get the node's ``tf_prefix``, unless already under it (see `resolve_frame_once`).
"""

from __future__ import annotations

import math
import shlex
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from fleetsim.errors import ParameterError
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.runtime import Node
from fleetsim.tf._msgs import make_transform_stamped
from fleetsim.tf.broadcaster import StaticTransformBroadcaster, TransformBroadcaster
from fleetsim.tf.names import resolve_frame_once
from fleetsim.tf.quaternions import quaternion_from_euler

__all__ = ["StaticTransform", "StaticTransformPublisher", "static_transform_from_args"]

USAGE = (
    "usage: static_transform_publisher x y z yaw pitch roll frame_id child_frame_id "
    "[period_in_ms] | x y z qx qy qz qw frame_id child_frame_id [period_in_ms] | "
    "--x X --y Y --z Z [--yaw --pitch --roll | --qx --qy --qz --qw] --frame-id F "
    "--child-frame-id C"
)
_EULER = ("x", "y", "z", "yaw", "pitch", "roll", "frame_id", "child_frame_id", "period_in_ms")
_QUAT = ("x", "y", "z", "qx", "qy", "qz", "qw", "frame_id", "child_frame_id", "period_in_ms")
_FLAGS = ("x", "y", "z", "qx", "qy", "qz", "qw", "roll", "pitch", "yaw")


@dataclass(frozen=True, slots=True)
class StaticTransform:
    """A parsed command line: child in parent, and the period (``None``: latched /tf_static)."""

    translation: tuple[float, float, float]
    rotation: tuple[float, float, float, float]
    frame_id: str
    child_frame_id: str
    period: float | None  # seconds


def _number(value: str, name: str, position: int, count: int) -> float:
    try:
        x = float(value)
    except ValueError:
        x = math.nan
    if not math.isfinite(x):
        raise ParameterError(
            f"static_transform_publisher argument {name!r} ({position} of {count}) must be a "
            f"finite number, got {value!r}; {USAGE}"
        )
    return x


def _is_number(value: str) -> bool:
    try:
        return math.isfinite(float(value))
    except ValueError:
        return False


def _unit_quaternion(q: Sequence[float], where: str) -> tuple[float, float, float, float]:
    n = math.sqrt(sum(v * v for v in q))
    if n < 1e-9:
        raise ParameterError(
            f"static_transform_publisher {where}: quaternion {tuple(q)} has zero length; the "
            "identity rotation is qx=0 qy=0 qz=0 qw=1"
        )
    qx, qy, qz, qw = (v / n for v in q)
    return qx, qy, qz, qw


def _from_flags(args: list[str]) -> StaticTransform:
    values: dict[str, float] = {}
    frames: dict[str, str] = {}
    i = 0
    while i < len(args):
        flag = args[i]
        key = flag[2:].replace("_", "-") if flag.startswith("--") else None
        if key is None or i + 1 >= len(args):
            raise ParameterError(
                f"static_transform_publisher: expected '--name value' pairs, got {flag!r} "
                f"at position {i + 1}; {USAGE}"
            )
        if key in ("frame-id", "child-frame-id"):
            frames[key] = args[i + 1]
        elif key in _FLAGS:
            values[key] = _number(args[i + 1], key, i + 2, len(args))
        else:
            raise ParameterError(f"static_transform_publisher: unknown flag {flag!r}; {USAGE}")
        i += 2
    if "frame-id" not in frames or "child-frame-id" not in frames:
        raise ParameterError(
            "static_transform_publisher: --frame-id and --child-frame-id are required; " + USAGE
        )
    has_quat = any(k in values for k in ("qx", "qy", "qz", "qw"))
    has_euler = any(k in values for k in ("roll", "pitch", "yaw"))
    if has_quat and has_euler:
        raise ParameterError(
            "static_transform_publisher: give the rotation either as --qx --qy --qz --qw or as "
            "--roll --pitch --yaw, not both"
        )
    if has_quat:
        q = [values.get(k, 0.0) for k in ("qx", "qy", "qz")] + [values.get("qw", 1.0)]
        rotation = _unit_quaternion(q, "--qx --qy --qz --qw")
    else:
        rpy = (values.get("roll", 0.0), values.get("pitch", 0.0), values.get("yaw", 0.0))
        rotation = tuple(float(v) for v in quaternion_from_euler(*rpy))
    translation = (values.get("x", 0.0), values.get("y", 0.0), values.get("z", 0.0))
    return StaticTransform(
        translation, rotation, frames["frame-id"], frames["child-frame-id"], None
    )


def static_transform_from_args(args: Sequence[str] | str) -> StaticTransform:
    """Parse ``static_transform_publisher`` arguments (any of the forms in the module doc).

    Raises
    ------
    ParameterError
        For a wrong argument count, a value that is not a number (naming the argument and its
        position), a zero quaternion, a period that is not positive, or equal frames.
    """
    items = args.split() if isinstance(args, str) else [str(a) for a in args]
    if len(items) == 1 and " " in items[0].strip():
        items = items[0].split()
    if any(a.startswith("--") for a in items):
        spec = _from_flags(items)
    else:
        n = len(items)
        if n == 9:  # tf's euler + period, or tf2_ros's quaternion without period
            if _is_number(items[6]) and not _is_number(items[8]):
                names = _QUAT[:9]
            elif _is_number(items[8]) and not _is_number(items[6]):
                names = _EULER
            else:
                raise ParameterError(
                    "static_transform_publisher: 9 arguments are either 'x y z yaw pitch roll "
                    "frame_id child_frame_id period_in_ms' or 'x y z qx qy qz qw frame_id "
                    f"child_frame_id', and {items!r} is neither"
                )
        elif n in (8, 10):
            names = _EULER[:8] if n == 8 else _QUAT
        else:
            raise ParameterError(
                f"static_transform_publisher: expected 8, 9 or 10 arguments, got {n} "
                f"({' '.join(items)!r}); {USAGE}"
            )
        nums = {
            name: _number(v, name, i + 1, n)
            for i, (name, v) in enumerate(zip(names, items))
            if name not in ("frame_id", "child_frame_id")
        }
        frame_id = items[names.index("frame_id")]
        child = items[names.index("child_frame_id")]
        if "qw" in nums:
            rotation = _unit_quaternion([nums[k] for k in ("qx", "qy", "qz", "qw")], "args")
        else:
            q = quaternion_from_euler(nums["roll"], nums["pitch"], nums["yaw"])
            rotation = tuple(float(v) for v in q)
        period = None
        if "period_in_ms" in nums:
            if not nums["period_in_ms"] > 0:
                raise ParameterError(
                    "static_transform_publisher argument 'period_in_ms' must be > 0 "
                    f"(100 ms is usual), got {items[-1]!r}"
                )
            period = nums["period_in_ms"] / 1000.0
        spec = StaticTransform((nums["x"], nums["y"], nums["z"]), rotation, frame_id, child, period)
    if spec.frame_id.strip("/") == spec.child_frame_id.strip("/"):
        raise ParameterError(
            f"static_transform_publisher: frame_id and child_frame_id are both "
            f"{spec.frame_id!r}; a frame cannot be its own parent"
        )
    return spec


class StaticTransformPublisher(Node):
    """Publishes one fixed transform: periodically on ``/tf`` (tf) or latched on ``/tf_static``.

    Parameters
    ----------
    runtime, name, namespace, **kw
        As for `fleetsim.runtime.Node`; the transform comes from ``args=`` (see module doc),
        a list of strings or one string.
    """

    def __init__(
        self, runtime: Any, name: str = "static_transform_publisher", namespace: str = "/", **kw
    ) -> None:
        if isinstance(kw.get("args"), str):  # one command-line string, as in a launch file
            kw["args"] = shlex.split(kw["args"])
        super().__init__(runtime, name, namespace, **kw)
        spec = static_transform_from_args(self.args)
        prefix = self.tf_prefix
        self.frame_id = resolve_frame_once(prefix, spec.frame_id)
        self.child_frame_id = resolve_frame_once(prefix, spec.child_frame_id)
        self.spec = spec
        if spec.period is None:
            self.broadcaster: Any = StaticTransformBroadcaster(self)
            self.broadcaster.send_transform(self._transform(self.now_msg()))
        else:
            self.broadcaster = TransformBroadcaster(self)
            self._publish()
            self.create_timer(spec.period, self._publish)

    def _transform(self, stamp: Time) -> Any:
        s = self.spec
        return make_transform_stamped(
            self.frame_id, self.child_frame_id, stamp, s.translation, s.rotation
        )

    def _publish(self) -> None:
        # tf's static_transform_publisher post-dates by one period
        period_ns = round(self.spec.period * 1e9)
        stamp = Time.from_nsec(self.runtime.time_ns + period_ns)
        self.broadcaster.send_transform(self._transform(stamp))
