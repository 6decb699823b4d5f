"""Command-line tools against a running simulation: rostopic, rosservice, rosparam, rosnode,
a move_base goal, RViz's initial pose, tf_echo and view_frames.

Every command connects as a zenoh client to ``--connect`` (default ``$FLEETSIM_ZENOH`` or
``tcp/127.0.0.1:7447``); with nothing there it fails in one line within about two seconds.
Bad input (YAML, types, fields) raises a `FleetsimError` that ``fleetsim`` prints in one line;
the simulation never sees it. The lead adds the apps in ``cli/main.py`` and calls `register`.
"""

from __future__ import annotations

import math
import time as _wall
from contextlib import contextmanager
from typing import Any

import typer

from fleetsim.errors import TransportError
from fleetsim.transport.client import SimulationClient

CONNECT_HELP = "Simulation endpoint (zenoh locator); default $FLEETSIM_ZENOH or tcp/127.0.0.1:7447."
Connect = typer.Option(None, "--connect", "-c", envvar="FLEETSIM_ZENOH", help=CONNECT_HELP)


#: lets coordinates like ``-2.5`` through as arguments instead of unknown options
NEGATIVE_NUMBERS = {"ignore_unknown_options": True}


def _app(help_text: str) -> typer.Typer:
    return typer.Typer(help=help_text, no_args_is_help=True, add_completion=False)


topic_app = _app("Topics: list, info, echo, hz, pub (like rostopic).")
service_app = _app("Services: list, call (like rosservice).")
param_app = _app("The parameter server: list, get, set, dump (like rosparam).")
node_app = _app("Nodes: list, and run one in this process joined to a simulation.")
tf_app = _app("tf: echo a transform, draw the tree (like tf_echo and view_frames).")


@contextmanager
def _client(connect: str | None, timeout: float = 2.0):
    client = SimulationClient(connect, timeout=timeout)
    try:
        yield client
    finally:
        client.close()


def _global(name: str) -> str:
    return name if name.startswith("/") else "/" + name


# -- topic ------------------------------------------------------------------------------------
@topic_app.command("list")
def topic_list(
    verbose: bool = typer.Option(False, "--verbose", "-v", help="Types and endpoint counts."),
    connect: str | None = Connect,
) -> None:
    """Print the topics of every process."""
    with _client(connect) as c:
        for name, t in c.graph()["topics"].items():
            if verbose:
                typer.echo(
                    f"{name} [{t['type']}] {len(t['publishers'])} publishers, "
                    f"{len(t['subscribers'])} subscribers"
                )
            else:
                typer.echo(name)


@topic_app.command("info")
def topic_info(topic: str, connect: str | None = Connect) -> None:
    """Type, publishers and subscribers of TOPIC."""
    from fleetsim.errors import GraphError, did_you_mean

    name = _global(topic)
    with _client(connect) as c:
        topics = c.graph()["topics"]
        t = topics.get(name)
        if t is None:
            raise GraphError(f"unknown topic {name}{did_you_mean(name, topics)}")
        lines = [f"Type: {t['type']}", "", "Publishers: "]
        lines += [f" * {n}" for n in t["publishers"]] or [" None"]
        lines += ["", "Subscribers: "]
        lines += [f" * {n}" for n in t["subscribers"]] or [" None"]
        typer.echo("\n".join(lines))


@topic_app.command("echo")
def topic_echo(
    topic: str,
    once: bool = typer.Option(False, "--once", help="Print one message and exit."),
    count: int | None = typer.Option(None, "-n", help="Print N messages and exit."),
    timeout: float | None = typer.Option(None, "--timeout", help="Give up after S wall seconds."),
    noarr: bool = typer.Option(False, "--noarr", help="Summarise arrays instead of printing."),
    connect: str | None = Connect,
) -> None:
    """Print messages on TOPIC as YAML documents (like rostopic echo)."""
    from fleetsim.transport.topic_tools import echo

    with _client(connect) as c:
        echo(c, _global(topic), typer.echo, 1 if once else count, timeout, noarr)


@topic_app.command("hz")
def topic_hz(
    topic: str,
    window: int = typer.Option(1000, "--window", "-w", help="Messages in the rolling window."),
    duration: float | None = typer.Option(None, "--duration", help="Stop after S wall seconds."),
    connect: str | None = Connect,
) -> None:
    """Publishing rate of TOPIC in sim time (like rostopic hz), reported every second."""
    from fleetsim.transport.topic_tools import hz

    with _client(connect) as c:
        hz(c, _global(topic), typer.echo, window, duration)


@topic_app.command("pub")
def topic_pub(
    topic: str,
    msg_type: str = typer.Argument(
        ..., metavar="TYPE", help="geometry_msgs/PoseStamped or .../msg/..."
    ),
    values: str = typer.Argument("", metavar="YAML", help="Field values, e.g. '{data: hi}'."),
    once: bool = typer.Option(False, "-1", "--once", help="Publish once and exit (default)."),
    rate: float | None = typer.Option(None, "-r", "--rate", help="Publish at RATE Hz (wall)."),
    count: int | None = typer.Option(None, "-n", help="With -r: stop after N messages."),
    wait: float = typer.Option(2.0, "--wait", help="Seconds to wait for a subscriber first."),
    connect: str | None = Connect,
) -> None:
    """Publish one message (or at RATE Hz) on TOPIC; ``stamp: now`` means the sim time."""
    from fleetsim.transport.textout import parse_yaml_arg
    from fleetsim.transport.topic_tools import publish

    name = _global(topic)
    data = parse_yaml_arg(values, f"topic pub {name}")
    with _client(connect) as c:
        publish(c, name, msg_type, data, typer.echo, None if once else rate, count, wait)


# -- service ----------------------------------------------------------------------------------
@service_app.command("list")
def service_list(
    verbose: bool = typer.Option(False, "--verbose", "-v", help="Types and providing nodes."),
    connect: str | None = Connect,
) -> None:
    """Print the services of every process."""
    with _client(connect) as c:
        for name, s in c.graph()["services"].items():
            typer.echo(f"{name} [{s['type']}] {s['node']}" if verbose else name)


@service_app.command("call")
def service_call(
    service: str,
    values: str = typer.Argument("", metavar="YAML", help="Request fields, e.g. '{data: true}'."),
    timeout: float = typer.Option(10.0, "--timeout", help="Seconds to wait for the response."),
    connect: str | None = Connect,
) -> None:
    """Call SERVICE with a YAML request and print the response."""
    from fleetsim.msgs import from_dict, get_srv_type, to_dict
    from fleetsim.transport.textout import parse_yaml_arg, yaml_text

    name = _global(service)
    data = parse_yaml_arg(values, f"service call {name}")
    with _client(connect) as c:
        srv_type = get_srv_type(c.service_type(name))
        request = from_dict(srv_type.Request, data, where=f"service call {name}")
        response = c.call_service(name, request, srv_type, timeout=timeout)
        text = yaml_text(to_dict(response)) if response.__msgfields__ else "{}\n"
        typer.echo(text, nl=False)


# -- param ------------------------------------------------------------------------------------
@param_app.command("list")
def param_list(namespace: str = typer.Argument("/"), connect: str | None = Connect) -> None:
    """Print the names of every parameter under NAMESPACE."""
    with _client(connect) as c:
        for name in c.param("list", _global(namespace)):
            typer.echo(name)


@param_app.command("get")
def param_get(name: str, connect: str | None = Connect) -> None:
    """Print a parameter's value (a namespace as YAML)."""
    from fleetsim.transport.textout import yaml_text

    with _client(connect) as c:
        value = c.param("get", _global(name))
    typer.echo(yaml_text(value) if isinstance(value, dict | list) else _scalar(value), nl=False)


def _scalar(value: Any) -> str:
    import yaml

    text = yaml.safe_dump(value)
    return text[: -len("...\n")] if text.endswith("...\n") else text


@param_app.command("set", context_settings=NEGATIVE_NUMBERS)
def param_set(
    name: str, value: str = typer.Argument(..., help="YAML value"), connect: str | None = Connect
) -> None:
    """Set a parameter (VALUE is YAML: 3, 0.5, true, '[1, 2]', '{a: 1}')."""
    from fleetsim.transport.textout import parse_yaml_arg

    parsed = parse_yaml_arg(value, f"param set {name}")
    with _client(connect) as c:
        c.param("set", _global(name), "" if parsed is None else parsed)


@param_app.command("dump")
def param_dump(
    namespace: str = typer.Argument("/"),
    output: str | None = typer.Option(None, "--output", "-o", help="Write to FILE instead."),
    connect: str | None = Connect,
) -> None:
    """Print (or write) every parameter under NAMESPACE as YAML."""
    from pathlib import Path

    from fleetsim.transport.textout import yaml_text

    with _client(connect) as c:
        text = yaml_text(c.param("dump", _global(namespace)))
    if output:
        Path(output).write_text(text)
    else:
        typer.echo(text, nl=False)


# -- node -------------------------------------------------------------------------------------
@node_app.command("list")
def node_list(connect: str | None = Connect) -> None:
    """Print the nodes of every process."""
    with _client(connect) as c:
        for name in c.graph()["nodes"]:
            typer.echo(name)


PARAMS = typer.Option(None, "--param", "-p", help="Private parameter k:=v (YAML value).")
REMAPS = typer.Option(None, "--remap", "-r", help="Remap from:=to.")


@node_app.command("run")
def node_run(
    spec: str = typer.Argument(..., metavar="MODULE:CLASS"),
    ns: str = typer.Option("/", "--ns", help="Namespace of the node."),
    name: str | None = typer.Option(None, "--name", help="Node name (default: the class's)."),
    param: list[str] | None = PARAMS,
    remap: list[str] | None = REMAPS,
    seed: int = typer.Option(0, "--seed", help="Seed of this process's random numbers."),
    until: float | None = typer.Option(None, "--until", help="Stop at this sim time (s)."),
    clock_timeout: float = typer.Option(
        30.0, "--clock-timeout", help="Wall seconds to wait for the simulation's first /clock."
    ),
    connect: str | None = Connect,
) -> None:
    """Run a node in this process on the simulation's /clock, joined to its graph.

    Ctrl-C (exit status 130) and SIGTERM (0) stop it between scheduler steps: the signal sets
    an event the clock-following loop checks, rather than raising KeyboardInterrupt wherever
    the main thread happens to be (inside a callback, holding a lock a Zenoh thread waits for,
    which then kept the session's close from returning). A second Ctrl-C interrupts at once.
    """
    import signal
    import threading

    from fleetsim.transport.noderun import parse_assignments, run_node

    stop = threading.Event()
    got: list[int] = []

    def on_signal(signum, _frame) -> None:
        if signum == signal.SIGINT and got:
            raise KeyboardInterrupt  # asked twice: no more waiting
        got.append(signum)
        stop.set()

    previous = {s: signal.signal(s, on_signal) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        run_node(
            spec,
            ns,
            name=name,
            params=parse_assignments(param or [], "--param"),
            remaps=parse_assignments(remap or [], "--remap"),
            connect=connect,
            seed=seed,
            until=until,
            stop=stop,
            clock_timeout=clock_timeout,
        )
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
    if got and got[0] == signal.SIGINT:
        raise typer.Exit(130)


# -- tf ---------------------------------------------------------------------------------------
@tf_app.command("echo")
def tf_echo(
    source: str,
    target: str,
    count: int | None = typer.Option(None, "-n", help="Print N times and exit."),
    rate: float = typer.Option(1.0, "--rate", help="Prints per wall second."),
    connect: str | None = Connect,
) -> None:
    """Print TARGET's pose in SOURCE (like tf_echo SOURCE TARGET)."""
    from fleetsim.errors import TransformError
    from fleetsim.transport.tfview import TfListener, echo_text

    if not rate > 0:
        raise TransportError(f"tf echo: rate must be > 0, got {rate}")
    with _client(connect) as c:
        tf = TfListener(c)
        printed, tries = 0, 0
        _wall.sleep(min(1.0, 1.0 / rate))
        while count is None or printed < count:
            try:
                typer.echo(echo_text(tf.lookup(source, target)))
                printed += 1
            except TransformError as e:
                tries += 1
                if tries * min(1.0, 1.0 / rate) > 5.0 and printed == 0:
                    raise
                typer.echo(f"Failure: {e}", err=True)
            _wall.sleep(1.0 / rate)


@tf_app.command("tree")
def tf_tree(
    output: str | None = typer.Option(None, "--output", "-o", help="frames.pdf/.png/.svg/.gv"),
    duration: float = typer.Option(2.0, "--duration", help="Seconds to listen (view_frames: 5)."),
    connect: str | None = Connect,
) -> None:
    """The tf tree with broadcasters and average rates (like view_frames)."""
    from fleetsim.transport.tfview import TfListener, frames_text, write_frames

    with _client(connect) as c:
        tf = TfListener(c)
        typer.echo(f"Listening to /tf for {duration:g} seconds", err=True)
        _wall.sleep(duration)
        infos = tf.frames()
        if not infos:
            raise TransportError("no transforms received on /tf or /tf_static")
        if output:
            path = write_frames(tf.dot(c.sim_time()), output)
            typer.echo(f"wrote {path}")
        else:
            typer.echo(frames_text(infos), nl=False)


# -- goal and initialpose -----------------------------------------------------------------------
def yaw_note(yaw: float) -> str | None:
    """A note for a yaw of more than a turn, most likely degrees typed for radians (90 for a
    quarter turn); None otherwise. The pose is sent as given either way, as rostopic would."""
    if abs(yaw) <= 2 * math.pi:
        return None
    return (
        f"note: yaw {yaw:g} rad is more than a full turn; yaw is in radians "
        f"({yaw:g} degrees would be {math.radians(yaw):.4f})"
    )


def _say_yaw(yaw: float) -> None:
    note = yaw_note(yaw)
    if note:
        typer.echo(note, err=True)


def goal(
    ns: str = typer.Argument(..., metavar="NS", help="Robot namespace, e.g. lizi1."),
    x: float = typer.Argument(..., help="Goal x, m."),
    y: float = typer.Argument(..., help="Goal y, m."),
    yaw: float = typer.Argument(0.0, help="Goal heading, rad."),
    frame: str = typer.Option("map", "--frame", help="Frame of the goal pose."),
    wait: bool = typer.Option(False, "--wait", help="Print feedback until the result."),
    timeout: float | None = typer.Option(None, "--timeout", help="With --wait: give up after S."),
    connect: str | None = Connect,
) -> None:
    """Send a move_base goal to robot NS (an action client: feedback and result)."""
    from fleetsim.transport.goal import cancel_goal, send_goal, status_name, yaw_of

    last = {"t": 0.0}

    def on_feedback(fb: Any) -> None:
        if _wall.monotonic() - last["t"] < 1.0:
            return
        last["t"] = _wall.monotonic()
        p = getattr(fb, "base_position", None)
        if p is not None:
            pos = p.pose.position
            typer.echo(
                f"feedback: x={pos.x:.2f} y={pos.y:.2f} yaw={yaw_of(p.pose.orientation):.2f}"
            )

    _say_yaw(yaw)
    with _client(connect) as c:
        gid = None
        try:
            # feedback only with --wait: without it, feedback of the new goal that arrived
            # before its status was printed above "goal sent" (a race the CLI test lost once)
            gid, status, text = send_goal(
                c, ns, x, y, yaw, frame, wait=wait, timeout=timeout,
                on_feedback=on_feedback if wait else None,
            )  # fmt: skip
        except KeyboardInterrupt:
            if gid is not None:
                cancel_goal(c, ns, gid)
            raise
        line = f"{'result' if wait else 'goal sent'}: {status_name(status)}"
        typer.echo(f"{line} ({text})" if text else line)
        if wait and status_name(status) != "SUCCEEDED":
            raise typer.Exit(1)


def initialpose(
    ns: str = typer.Argument(..., metavar="NS", help="Robot namespace, e.g. lizi1."),
    x: float = typer.Argument(...),
    y: float = typer.Argument(...),
    yaw: float = typer.Argument(...),
    frame: str = typer.Option("map", "--frame"),
    connect: str | None = Connect,
) -> None:
    """Set robot NS's pose estimate (PoseWithCovarianceStamped on NS/initialpose, as RViz)."""
    from fleetsim.transport.goal import publish_initial_pose

    _say_yaw(yaw)
    with _client(connect) as c:
        topic = publish_initial_pose(c, ns, x, y, yaw, frame)
    typer.echo(f"published initial pose on {topic}")


def register(app: typer.Typer) -> None:
    """Add the single commands ``goal`` and ``initialpose`` to the main app (the sub-apps
    ``topic_app`` ... ``tf_app`` are added by name in ``cli/main.py``)."""
    app.command("goal", context_settings=NEGATIVE_NUMBERS)(goal)
    app.command("initialpose", context_settings=NEGATIVE_NUMBERS)(initialpose)


__all__ = ["node_app", "param_app", "register", "service_app", "tf_app", "topic_app"]
