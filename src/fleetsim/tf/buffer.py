"""The tf buffer: time-stamped transforms between frames and lookups across the tree.

:class:`Buffer` behaves like tf2's ``BufferCore``: each child frame keeps a time-sorted cache of
its transform to its parent over a ``cache_time`` window; static transforms hold at all times; a
lookup walks from both frames to their common ancestor, interpolating each edge between the two
stamps that bracket the requested time (linear translation, slerp rotation). Time ``0`` (or
``None``) asks for the latest time at which every edge of the chain has data.

Differences from tf2, on purpose: re-publishing a stamp that is already cached replaces the
entry (as ROS 2's tf2 does); a frame that gets a new parent (or switches between static and
dynamic) drops its history, since the earlier stamps describe a different edge; a transform that
would close a loop is rejected when it is set, not when it is looked up.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from typing import Any

import numpy as np

from fleetsim.errors import (
    ConnectivityError,
    FrameNotFound,
    InvalidName,
    ParameterError,
    TransformError,
    did_you_mean,
)
from fleetsim.tf import _msgs
from fleetsim.tf.cache import FrameCache, checked_value, ns_from_time
from fleetsim.tf.fastmath import IDENTITY, Transform7, compose, invert, matrix_rows
from fleetsim.tf.frame_info import FrameInfo, TreeIntrospection
from fleetsim.tf.geometry import TRANSFORMERS
from fleetsim.tf.names import normalize_frame

__all__ = ["Buffer", "FrameInfo"]

_log = logging.getLogger("fleetsim.tf")

#: How many known frames an error message lists before it says "... and N more".
_MAX_LISTED_FRAMES = 12


class Buffer(TreeIntrospection):
    """Transforms between coordinate frames over time (tf2's ``BufferCore``).

    Parameters
    ----------
    cache_time : float
        Seconds of history kept per frame, counted back from that frame's newest stamp.
    """

    def __init__(self, cache_time: float = 10.0) -> None:
        if not (
            isinstance(cache_time, int | float) and cache_time > 0 and math.isfinite(cache_time)
        ):
            raise ParameterError(
                f"tf Buffer cache_time must be a positive number of seconds, got {cache_time!r}"
            )
        self.cache_time = float(cache_time)
        self._cache_ns = round(self.cache_time * 1e9)
        self._frames: dict[str, FrameCache] = {}
        self._version = 0  # bumped whenever an edge of the tree appears, moves or disappears
        self._paths: dict[tuple[str, str], tuple[int, list[FrameCache], list[FrameCache]]] = {}
        self._rejected: set[tuple[str, str]] = set()  # (child, authority) already warned about
        # see call_after_next_message: (callback, the child frames it waits on or None: any)
        self._waiting: list[tuple[Callable[[], Any], frozenset[str] | None]] = []

    # ------------------------------------------------------------------ writing
    def add_message(self, msg: Any, authority: str = "", is_static: bool = False) -> int:
        """Add every transform of a ``tf2_msgs/TFMessage``, as tf2's listener does: a bad one
        (NaN, self parent, a loop, an empty frame) is logged, naming its frame and publisher,
        and skipped; the others still go in. Returns how many were added."""
        added = 0
        touched: set[str] = set()
        version = self._version
        for t in msg.transforms:
            try:
                self.set_transform(t, authority=authority, is_static=is_static)
                added += 1
                if self._waiting:
                    touched.add(normalize_frame(t.child_frame_id))
            except (TransformError, InvalidName) as exc:
                key = (str(t.child_frame_id), authority)
                if key not in self._rejected:  # once per frame and publisher, not per message
                    self._rejected.add(key)
                    _log.error("ignoring transform for %r: %s", t.child_frame_id, exc)
        if added and self._waiting:
            moved = self._version != version  # the tree changed: every chain may have
            due = [
                w for w in self._waiting if moved or w[1] is None or not w[1].isdisjoint(touched)
            ]
            if due:
                self._waiting = [w for w in self._waiting if w not in due]
                for callback, _ in due:
                    callback()
        return added

    def call_after_next_message(
        self, callback: Callable[[], Any], frames: frozenset[str] | None = None
    ) -> None:
        """Call ``callback()`` once, after the next message that adds a transform (with
        ``frames``: a transform to one of those child frames, see `edges_between`).

        What tf2's message filters wait on (``BufferCore::addTransformableCallback``, which
        waits on its request's frames): a node holding data whose transform has not arrived
        retries when tf changes, without each such node receiving every ``/tf`` message itself
        (N robots' nodes x N robots' transforms); with ``frames``, without retrying on the
        other robots' transforms either.
        """
        if all(cb != callback for cb, _ in self._waiting):
            self._waiting.append((callback, frames))

    def edges_between(self, target_frame: str, source_frame: str) -> frozenset[str] | None:
        """The child frames of the dynamic tf edges between two frames: the transforms a
        lookup between them waits on. None when they are not connected yet or only static
        edges join them (then any new transform may be the one that matters)."""
        try:
            down, up = self._chain(target_frame, source_frame)
        except (TransformError, InvalidName):
            return None
        edges = frozenset(f.name for f in (*down, *up) if not f.is_static)
        return edges or None

    def set_transform(self, transform: Any, authority: str = "", is_static: bool = False) -> bool:
        """Add one ``geometry_msgs/TransformStamped`` to the buffer.

        ``header.frame_id`` is the parent, ``child_frame_id`` the child; the transform maps points
        in the child frame into the parent frame. Returns ``False`` (and logs a warning, as tf2
        does) for data older than the cache window of that frame; ``True`` otherwise.

        Raises
        ------
        TransformError
            For a self transform, a non-finite value, a quaternion far from unit norm, or a
            transform that would close a loop in the tree.
        InvalidName
            For an empty frame id.
        """
        tr = transform.transform.translation
        q = transform.transform.rotation
        return self.set_transform_values(
            transform.header.frame_id,
            transform.child_frame_id,
            transform.header.stamp,
            (tr.x, tr.y, tr.z),
            (q.x, q.y, q.z, q.w),
            authority=authority,
            is_static=is_static,
        )

    def set_transform_values(
        self,
        parent_frame: str,
        child_frame: str,
        stamp: Any,
        translation: tuple[float, float, float],
        rotation: tuple[float, float, float, float],
        authority: str = "",
        is_static: bool = False,
    ) -> bool:
        """Like :meth:`set_transform`, from plain values.

        ``stamp`` is float seconds or a ``builtin_interfaces/Time``; ``translation`` is
        ``(x, y, z)`` metres and ``rotation`` a quaternion ``(x, y, z, w)``, child in parent.
        """
        parent = normalize_frame(parent_frame)
        child = normalize_frame(child_frame)
        if parent == child:
            raise TransformError(
                f"transform from {authority or 'default_authority'!r} has child_frame_id equal to "
                f"frame_id {child!r}; a frame cannot be its own parent"
            )
        value = checked_value(parent, child, translation, rotation)
        stamp_ns = ns_from_time(stamp)
        frames = self._frames
        f = frames.get(child)
        if f is None:
            f = frames[child] = FrameCache(child)
        if f.parent != parent or f.is_static != is_static:
            self._check_no_loop(parent, child)
            if parent not in frames:
                frames[parent] = FrameCache(parent)
            f.reset(parent, is_static)
            self._version += 1
        f.authority = authority
        if f.insert(stamp_ns, value, self._cache_ns):
            return True
        _log.warning(
            "tf: ignoring %s -> %s at %.9f s from %s: older than the cache window "
            "(newest %.9f s, cache_time %g s)",
            parent, child, stamp_ns * 1e-9, authority or "default_authority",
            f.stamps[-1] * 1e-9, self.cache_time,
        )  # fmt: skip
        return False

    def clear(self) -> None:
        """Forget all dynamic transforms (as after a jump back in time); static ones stay."""
        for f in self._frames.values():
            if f.parent is not None and not f.is_static:
                f.reset(None, False)
        self._version += 1

    def _check_no_loop(self, parent: str, child: str) -> None:
        chain = [parent]
        node = self._frames.get(parent)
        while node is not None and node.parent is not None:
            chain.append(node.parent)
            if node.parent == child:
                path = " -> ".join(reversed([child, *chain]))
                raise TransformError(
                    f"setting {child!r} as a child of {parent!r} would close a loop in the tf "
                    f"tree (parent -> child: {path}); each frame has one parent, so find the "
                    f"node that publishes {child!r} with parent {parent!r}"
                )
            node = self._frames.get(node.parent)

    # ------------------------------------------------------------------ lookups
    def lookup_transform(self, target_frame: str, source_frame: str, time: Any = 0.0) -> Any:
        """Return the transform that maps points in ``source_frame`` into ``target_frame``.

        Parameters
        ----------
        target_frame, source_frame : str
            Frame ids; one leading ``/`` is ignored.
        time : float, builtin_interfaces/Time or None
            Sim time in seconds; ``0`` or ``None`` for the latest time common to the chain.

        Returns
        -------
        geometry_msgs/TransformStamped
            ``header.frame_id = target_frame``, ``child_frame_id = source_frame``,
            ``header.stamp`` the time used.

        Raises
        ------
        FrameNotFound, ConnectivityError, ExtrapolationError
        """
        stamp_ns, value, target, source = self._lookup(target_frame, source_frame, time)
        return _msgs.transform_stamped(target, source, stamp_ns, value)

    def lookup_transform_full(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
    ) -> Any:
        """Time-travelling lookup through a frame assumed fixed over time (tf2's advanced API).

        Returns the transform mapping points in ``source_frame`` at ``source_time`` into
        ``target_frame`` at ``target_time``, via ``fixed_frame``. The returned stamp is the
        later of the two resolved times.
        """
        t1, v1, target, _ = self._lookup(target_frame, fixed_frame, target_time)
        t2, v2, _, source = self._lookup(fixed_frame, source_frame, source_time)
        return _msgs.transform_stamped(target, source, max(t1, t2), compose(v1, v2))

    def transform(self, obj: Any, target_frame: str, time: Any = None) -> Any:
        """Return a stamped geometry message expressed in ``target_frame`` (tf2_ros ``transform``).

        Supports ``PointStamped``, ``Vector3Stamped``, ``PoseStamped`` and
        ``PoseWithCovarianceStamped``. The lookup uses ``obj.header.stamp`` (zero: latest)
        unless ``time`` is given.

        Raises
        ------
        TransformError
            For an unsupported message type; or the lookup's errors.
        """
        kind = getattr(obj, "__msgtype__", type(obj).__name__)
        fn = TRANSFORMERS.get(kind)
        if fn is None:
            raise TransformError(
                f"Buffer.transform cannot transform a {kind}; supported: "
                + ", ".join(sorted(TRANSFORMERS))
            )
        stamp = obj.header.stamp if time is None else time
        return fn(obj, self.lookup_transform(target_frame, obj.header.frame_id, stamp))

    def can_transform(self, target_frame: str, source_frame: str, time: Any = 0.0) -> bool:
        """Return whether :meth:`lookup_transform` with these arguments would succeed."""
        try:
            self._lookup(target_frame, source_frame, time)
        except TransformError:
            return False
        return True

    def lookup_arrays(self, target_frame: str, source_frame: str, time: Any = 0.0) -> tuple:
        """Fast path: ``(translation (3,), quaternion (4,))`` NumPy arrays, target <- source."""
        v = self._lookup(target_frame, source_frame, time)[1]
        return np.array(v[:3]), np.array(v[3:])

    def lookup_matrix(self, target_frame: str, source_frame: str, time: Any = 0.0) -> Any:
        """Fast path: the homogeneous 4x4 matrix mapping source points into the target frame."""
        return np.array(matrix_rows(self._lookup(target_frame, source_frame, time)[1]))

    def lookup_tuple(self, target_frame: str, source_frame: str, time: Any = 0.0) -> Transform7:
        """Fastest path: ``(tx, ty, tz, qx, qy, qz, qw)`` as plain floats, target <- source."""
        return self._lookup(target_frame, source_frame, time)[1]

    def lookup_pose2d(
        self, target_frame: str, source_frame: str, time: Any = 0.0
    ) -> tuple[float, float, float]:
        """Planar pose ``(x, y, yaw)`` of ``source_frame`` in ``target_frame`` (metres, radians)."""
        x, y, _, qx, qy, qz, qw = self._lookup(target_frame, source_frame, time)[1]
        return x, y, math.atan2(2.0 * (qw * qz + qx * qy), qw * qw + qx * qx - qy * qy - qz * qz)

    def latest_common_time(self, target_frame: str, source_frame: str) -> float:
        """Newest time (seconds) at which every edge between the two frames has data.

        ``0.0`` when the chain holds only static transforms (or the frames are the same).
        """
        down, up = self._path(target_frame, source_frame)
        return self._latest_ns(down, up) * 1e-9

    def _path(
        self, target_frame: str, source_frame: str
    ) -> tuple[list[FrameCache], list[FrameCache]]:
        """`_chain`, kept per frame pair while the tree's edges stay as they were (every
        costmap's robot pose asks for its pose and then its latest time, several times a
        cycle)."""
        entry = self._paths.get((target_frame, source_frame))
        if entry is not None and entry[0] == self._version:
            return entry[1], entry[2]
        return self._chain(target_frame, source_frame)

    def _lookup(
        self, target_frame: str, source_frame: str, time: Any
    ) -> tuple[int, Transform7, str, str]:
        down, up = self._path(target_frame, source_frame)
        t_ns = 0 if time is None else ns_from_time(time)
        if t_ns == 0:
            t_ns = self._latest_ns(down, up)
        if up:
            acc_s = up[0].value_at(t_ns, target_frame, source_frame)
            for f in up[1:]:
                acc_s = compose(f.value_at(t_ns, target_frame, source_frame), acc_s)
        else:
            acc_s = IDENTITY
        if down:
            acc_t = down[0].value_at(t_ns, target_frame, source_frame)
            for f in down[1:]:
                acc_t = compose(f.value_at(t_ns, target_frame, source_frame), acc_t)
            acc_s = compose(invert(acc_t), acc_s) if up else invert(acc_t)
        target = target_frame[1:] if target_frame[:1] == "/" else target_frame
        source = source_frame[1:] if source_frame[:1] == "/" else source_frame
        return t_ns, acc_s, target, source

    @staticmethod
    def _latest_ns(down: list[FrameCache], up: list[FrameCache]) -> int:
        latest = 0
        for f in up:
            if not f.is_static and (latest == 0 or f.stamps[-1] < latest):
                latest = f.stamps[-1]
        for f in down:
            if not f.is_static and (latest == 0 or f.stamps[-1] < latest):
                latest = f.stamps[-1]
        return latest

    def _chain(
        self, target_frame: str, source_frame: str
    ) -> tuple[list[FrameCache], list[FrameCache]]:
        """Frames from target and from source up to (excluding) their common ancestor."""
        target = normalize_frame(target_frame)
        source = normalize_frame(source_frame)
        frames = self._frames
        for name, role, other in (
            (target, "target_frame", source),
            (source, "source_frame", target),
        ):
            if name not in frames:
                raise self._not_found(name, role, other)
        chain_t = self._ancestors(target)
        chain_s = self._ancestors(source)
        index_s = {name: i for i, name in enumerate(chain_s)}
        for j, name in enumerate(chain_t):
            i = index_s.get(name)
            if i is not None:
                down = [frames[n] for n in chain_t[:j]]
                up = [frames[n] for n in chain_s[:i]]
                self._paths[(target_frame, source_frame)] = (self._version, down, up)
                return down, up
        raise ConnectivityError(
            f"cannot transform {source!r} into {target!r}: they are in disconnected tf trees "
            f"({target!r} is under root {chain_t[-1]!r}, {source!r} under root {chain_s[-1]!r}); "
            f"a transform linking {chain_t[-1]!r} and {chain_s[-1]!r} (e.g. from a localization "
            "node or a static_transform_publisher) would connect them"
        )

    def _prefixed_twins(self, name: str, other: str) -> str:
        """A hint when ``name`` is missing, it and ``other`` (the lookup's other frame) are
        bare, as a node without a tf_prefix asks for, and frames of that name under a tf_prefix
        exist (``lizi1/odom`` for ``odom``): robots in namespaces without a ``tf_prefix``
        parameter, whose simulated frames take the namespace while their nodes' stay bare. A
        lookup from a prefixed frame (``map`` -> ``hunter1/base_link`` while each hunter's
        gmapping publishes ``hunterN/map``) is another matter and gets no such hint."""
        if "/" in name or "/" in other:
            return ""
        twins = sorted(f for f in self._frames if f.rpartition("/")[2] == name and "/" in f)
        if not twins:
            return ""
        listed = ", ".join(twins[:4]) + (
            f" ... and {len(twins) - 4} more" if len(twins) > 4 else ""
        )
        return (
            f"; frames named {name!r} under a tf_prefix exist ({listed}): a node without a "
            "tf_prefix uses the bare name, while the simulator prefixes a robot's frames with "
            "its namespace; set the tf_prefix parameter in each robot's namespace (<param "
            f'name="tf_prefix" value="{twins[0].rpartition("/")[0]}"/> in its <group ns>) so '
            "that its nodes use it too"
        )

    def _ancestors(self, name: str) -> list[str]:
        chain = [name]
        f = self._frames[name]
        while f.parent is not None:
            chain.append(f.parent)
            f = self._frames[f.parent]
        return chain

    def _not_found(self, name: str, role: str, other: str = "/") -> FrameNotFound:
        known = sorted(self._frames)
        listed = ", ".join(known[:_MAX_LISTED_FRAMES]) or "none"
        if len(known) > _MAX_LISTED_FRAMES:
            listed += f" ... and {len(known) - _MAX_LISTED_FRAMES} more"
        hint = self._prefixed_twins(name, other) or did_you_mean(name, known)
        tail = name.rpartition("/")[2]
        if "/" in name and tail in self._frames:
            # a frame parameter written without its leading slash took a tf_prefix (ROS 1's
            # tf::resolve), and the shared frame exists unprefixed: the usual multi-robot slip
            hint = (
                f" ({tail!r} exists unprefixed: if it is the shared frame, write '/{tail}' (a "
                "frame written without a leading slash takes the node's tf_prefix); if it is "
                "this robot's own, its publisher lacks the tf_prefix)"
            )
        return FrameNotFound(
            f"{role} {name!r} does not exist in the tf tree{hint}; known frames: {listed}"
        )
