"""The runtime: one sim clock, one scheduler, one graph, one parameter tree, one seed."""

from __future__ import annotations

import atexit
import gc
import logging
import zlib
from collections.abc import Callable
from typing import Any

import numpy as np

from fleetsim.errors import FleetsimError
from fleetsim.runtime.graph import Graph
from fleetsim.runtime.params import ParamTree
from fleetsim.runtime.scheduler import NS, Scheduler, Timer, to_ns

_log = logging.getLogger("fleetsim.runtime")
# the collections at interpreter exit skip frozen objects too: without this, what a Runtime left
# unshut froze (`Runtime._freeze_heap`; such as extension types, freed only as cycles: OMPL's,
# which nanobind then reports as leaked) would never be freed nor finalised. A no-op when
# nothing is frozen.
atexit.register(gc.unfreeze)


class Runtime:
    """Owns time, the graph, parameters and randomness for one simulation.

    Parameters
    ----------
    seed : the one seed every random number in the run derives from.
    """

    def __init__(self, seed: int = 0) -> None:
        self.seed = int(seed)
        self.graph = Graph()
        self.params = ParamTree()
        self.scheduler = Scheduler(self.graph.drain)
        self._tf_buffer = None
        self._tf_subs: list = []
        self._shutdown_hooks: list[Callable[[], None]] = []
        self._is_shutdown = False
        self._heap_frozen = False

    # -- time -----------------------------------------------------------------------------
    def now(self) -> float:
        """Sim time in seconds."""
        return self.scheduler.time_ns / NS

    @property
    def time_ns(self) -> int:
        return self.scheduler.time_ns

    def create_timer(
        self, period: float, callback: Callable[[], None], priority: int = 0, **kw: Any
    ) -> Timer:
        return self.scheduler.create_timer(period, callback, priority, **kw)

    def call_later(self, delay: float, callback: Callable[[], None], priority: int = 0) -> Timer:
        """Run ``callback`` once, ``delay`` seconds of sim time from now."""
        return self.scheduler.create_timer(
            0.0, callback, priority, oneshot=True, start=self.now() + max(0.0, delay)
        )

    # -- running --------------------------------------------------------------------------
    def run(
        self,
        duration: float | None = None,
        until: Callable[[], bool] | None = None,
        rate: float | None = None,
    ) -> None:
        """Advance sim time by ``duration`` seconds (or forever), or until ``until()`` is true.

        ``rate`` paces the run against the wall clock (1.0 = real time); None runs as fast as
        it can.
        """
        if self._is_shutdown:
            raise FleetsimError("this runtime was shut down; create a new Runtime to run again")
        if rate is not None and not rate > 0:
            raise FleetsimError(f"rate must be > 0 (1.0 is real time), got {rate!r}")
        end = None if duration is None else self.scheduler.time_ns + to_ns(duration)
        if end is None and until is None:
            raise FleetsimError("run() needs a duration or an until condition (or both)")
        if not self._heap_frozen:
            self._freeze_heap()
        self.scheduler.run(end, until, rate)

    def _freeze_heap(self) -> None:
        """Leave what exists when the run starts (modules, models, nodes, costmaps: ~200,000
        objects for ten robots) out of Python's full garbage collections (``gc.freeze``), which
        otherwise walk all of it every few seconds (~0.2 s each, 3-4 % of a fleet's run) to
        free the few short-lived cycles a run makes; those are still collected. Undone at
        `shutdown`, so that a finished run's own cycles can be freed; and at interpreter exit,
        for a Runtime never shut down."""
        self._heap_frozen = True
        gc.freeze()

    def spin_once(self) -> int:
        """Deliver pending messages without advancing time; returns how many were delivered."""
        return self.graph.drain()

    def stop(self) -> None:
        """Make a running `run` return after the current callback."""
        self.scheduler.stop()

    def on_shutdown(self, hook: Callable[[], None]) -> None:
        self._shutdown_hooks.append(hook)

    def shutdown(self) -> None:
        """Destroy every node and run the shutdown hooks (recorders finalise here)."""
        if self._is_shutdown:
            return
        self._is_shutdown = True
        if self._heap_frozen:
            gc.unfreeze()
        errors = []
        for node in list(self.graph.nodes.values()):
            try:
                node.destroy()
            except Exception as e:  # keep shutting the others down
                errors.append(e)
        for hook in reversed(self._shutdown_hooks):
            try:
                hook()
            except Exception as e:
                errors.append(e)
        if errors:
            raise errors[0]

    def __enter__(self) -> Runtime:
        return self

    def __exit__(self, *exc: object) -> None:
        self.shutdown()

    # -- randomness -----------------------------------------------------------------------
    def rng(self, name: str) -> np.random.Generator:
        """A generator for ``name`` (a node or plugin), derived from the run's seed.

        The same seed and name give the same stream, whatever else the run contains.
        """
        return np.random.default_rng([self.seed, zlib.crc32(name.encode())])

    # -- tf -----------------------------------------------------------------------------
    @property
    def tf_buffer(self):
        """The run's tf buffer, fed by ``/tf`` and ``/tf_static`` (created on first use)."""
        if self._tf_buffer is None:
            from fleetsim.msgs import tf2_msgs
            from fleetsim.tf.buffer import Buffer

            buf = Buffer()

            def on_tf(msg, static=False):
                buf.add_message(msg, authority="", is_static=static)

            self._tf_subs = [
                self.graph.subscribe("/tf", tf2_msgs.TFMessage, on_tf, queue_size=0),
                self.graph.subscribe(
                    "/tf_static",
                    tf2_msgs.TFMessage,
                    lambda m: on_tf(m, static=True),
                    queue_size=0,
                ),
            ]
            self._tf_buffer = buf
        return self._tf_buffer
