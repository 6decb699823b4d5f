"""The `FleetsimError` family.

Every error says what was wrong, where (file, line, field, parameter, topic, frame) and, when it
can, what would fix it. The CLI prints ``str(error)`` on one line without a traceback.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable


class FleetsimError(Exception):
    """Base of every error fleetsim raises on purpose."""


class InvalidName(FleetsimError):
    """An invalid graph resource name, remap or frame name."""


class ParameterError(FleetsimError):
    """A parameter with the wrong type, out of range, or a parameter file that does not parse."""


class GraphError(FleetsimError):
    """Misuse of the graph: a topic with two types, an unknown service, a duplicate node."""


class ServiceError(FleetsimError):
    """A service call that failed: no server, or the server raised."""


class ActionError(FleetsimError):
    """Misuse of an action server or client."""


class MessageError(FleetsimError):
    """An unknown message type, a field that does not exist, or bytes that do not decode."""


class TransformError(FleetsimError):
    """Base of tf lookup failures."""


class FrameNotFound(TransformError):
    """A frame that is not in the tree (tf2's LookupException)."""


class ConnectivityError(TransformError):
    """Two frames in disconnected trees."""


class ExtrapolationError(TransformError):
    """A lookup at a time outside the buffered window."""


class DescriptionError(FleetsimError):
    """A robot description (xacro, URDF, SRDF) that is invalid."""


class SimulationError(FleetsimError):
    """A world or simulator setup that cannot be built."""


class ControlError(FleetsimError):
    """ros_control: a controller that cannot be loaded, switched or commanded."""


class PlanningError(FleetsimError):
    """move_group: a bad planning request (group, target, limits) or a failed plan."""


class LaunchError(FleetsimError):
    """A launch file that cannot be read or run."""


class BatchError(FleetsimError):
    """A batch experiment that cannot run: a bad spec, sweep or results folder."""


class TransportError(FleetsimError):
    """Cross-process transport problems: no simulation running, a peer that does not answer."""


class RecordingError(FleetsimError):
    """An MCAP file that cannot be written or read."""


def did_you_mean(word: str, choices: Iterable[str]) -> str:
    """Return ``" (did you mean 'x'?)"`` for the closest choice, or ``""`` when none is close.

    A choice differing only in case comes first (``maxURange`` is gmapping's ``maxUrange``,
    which difflib ranks below ``maxRange``)."""
    choices = list(choices)
    same = [c for c in choices if c.lower() == word.lower() and c != word]
    close = same or difflib.get_close_matches(word, choices, n=1, cutoff=0.6)
    return f" (did you mean '{close[0]}'?)" if close else ""


class PhysicsInstability(SimulationError):
    """The physics blew up: NaN, infinite or huge accelerations, positions or velocities, a
    non-finite actuator command, or a singular inertia. The message names the robot, body and
    joint of the bad degree of freedom, the sim time, the likely cause and what to try."""


class PhysicsBufferFull(SimulationError):
    """MuJoCo ran out of room for contacts or constraints and dropped some: bodies would pass
    through each other."""
