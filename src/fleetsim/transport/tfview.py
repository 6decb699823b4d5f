"""``fleetsim tf echo`` and ``fleetsim tf tree``: tf_echo and view_frames against a simulation.

`TfListener` fills a local tf `Buffer` from ``/tf`` and ``/tf_static`` received over the bridge
(reader threads, hence the lock). The broadcaster of each frame is the publishing node the
simulation names in each sample (and in each latched ``/tf_static`` reply: one per publisher).
"""

from __future__ import annotations

import math
import shutil
import subprocess
import threading
from pathlib import Path
from typing import Any

from fleetsim.errors import TransformError, TransportError
from fleetsim.transport.client import Received, SimulationClient

#: the authority of a transform whose publisher has no node (tf2's default authority)
UNKNOWN_BROADCASTER = "default_authority"


class TfListener:
    """A tf buffer fed from a running simulation."""

    def __init__(self, client: SimulationClient, cache_time: float = 10.0) -> None:
        from fleetsim.tf import Buffer

        self.buffer = Buffer(cache_time)
        self.lock = threading.Lock()
        self.latest = 0.0
        client.subscribe("/tf", self._on_tf)
        client.subscribe("/tf_static", self._on_tf)

    def _on_tf(self, r: Received) -> None:
        if isinstance(r.msg, Exception):
            return
        static = r.topic == "/tf_static"
        authority = r.node or UNKNOWN_BROADCASTER
        with self.lock:
            for t in r.msg.transforms:
                try:
                    self.buffer.set_transform(t, authority=authority, is_static=static)
                except TransformError:
                    continue
                if not static:
                    self.latest = max(self.latest, t.header.stamp.to_sec())

    def lookup(self, source: str, target: str) -> Any:
        """tf_echo's transform: ``target``'s pose in ``source`` at the latest common time."""
        with self.lock:
            return self.buffer.lookup_transform(source, target, 0.0)

    def frames(self) -> dict:
        """`FrameInfo` of every child frame received so far."""
        with self.lock:
            return self.buffer.frames_info()

    def dot(self, recorded_at: float) -> str:
        """view_frames' Graphviz source of the tree (`Buffer.all_frames_as_dot`)."""
        with self.lock:
            return self.buffer.all_frames_as_dot(recorded_at)


def echo_text(t: Any) -> str:
    """What tf_echo prints for one transform."""
    from fleetsim.tf.quaternions import euler_from_quaternion

    tr, q = t.transform.translation, t.transform.rotation
    r, p, y = euler_from_quaternion([q.x, q.y, q.z, q.w])
    deg = [math.degrees(a) for a in (r, p, y)]
    return (
        f"At time {t.header.stamp.to_sec():.3f}\n"
        f"- Translation: [{tr.x:.3f}, {tr.y:.3f}, {tr.z:.3f}]\n"
        f"- Rotation: in Quaternion [{q.x:.3f}, {q.y:.3f}, {q.z:.3f}, {q.w:.3f}]\n"
        f"            in RPY (radian) [{r:.3f}, {p:.3f}, {y:.3f}]\n"
        f"            in RPY (degree) [{deg[0]:.3f}, {deg[1]:.3f}, {deg[2]:.3f}]"
    )


def frames_text(infos: dict) -> str:
    """The tree as indented text: ``child  [broadcaster, rate]`` under each parent."""
    children: dict[str, list[str]] = {}
    for name, f in infos.items():
        children.setdefault(f.parent or "", []).append(name)
    roots = sorted(p for p in children if p and p not in infos) + sorted(
        n for n in children.get("", [])
    )
    lines: list[str] = []

    def walk(frame: str, depth: int) -> None:
        f = infos.get(frame)
        if f is None:
            lines.append(f"{'  ' * depth}{frame}")
        else:
            rate = "static" if f.is_static else f"{f.rate or 0.0:.1f} Hz"
            lines.append(f"{'  ' * depth}{frame}  [{f.authority}, {rate}]")
        for c in sorted(children.get(frame, [])):
            walk(c, depth + 1)

    for root in dict.fromkeys(roots):
        walk(root, 0)
    return "\n".join(lines) + ("\n" if lines else "")


def write_frames(source: str, out: str | Path) -> Path:
    """Write the tree to ``out``: ``.gv``/``.dot`` as source, ``.pdf``/``.png``/``.svg`` via dot."""
    out = Path(out)
    fmt = out.suffix.lstrip(".").lower()
    if fmt in ("gv", "dot"):
        out.write_text(source)
        return out
    if fmt not in ("pdf", "png", "svg"):
        raise TransportError(f"tf tree: cannot write {out}: use a .pdf, .png, .svg or .gv name")
    exe = shutil.which("dot")
    if exe is None:
        raise TransportError(
            "Graphviz 'dot' was not found on PATH; install graphviz or write a .gv file"
        )
    proc = subprocess.run(
        [exe, f"-T{fmt}", "-o", str(out)], input=source, capture_output=True, text=True, check=False
    )
    if proc.returncode != 0:
        raise TransportError(f"{out}: graphviz dot failed: {proc.stderr.strip()}")
    return out
