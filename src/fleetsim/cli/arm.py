"""``fleetsim arm list|go``: a robot's planning groups and named poses, and move_group goals,
against a running simulation (over the Zenoh bridge, as the other tools).

``arm list`` reads ``<ns>/robot_description`` and ``<ns>/robot_description_semantic`` from the
parameter server; ``arm go`` checks the target against them here (unknown group or pose, a
value outside the joint limits: one clear error, nothing sent), then sends a MoveGroup goal on
``<ns>/move_group`` and prints its result with MoveIt's error code name.
"""

from __future__ import annotations

import time as _wall

import typer

from fleetsim.cli.tools import Connect, _client
from fleetsim.errors import PlanningError, TransportError
from fleetsim.runtime import names

app = typer.Typer(
    help="Arms: planning groups and named poses; move_group goals.",
    no_args_is_help=True,
    add_completion=False,
)


def _ns(ns: str) -> str:
    return names.validate_namespace("/" + ns.strip("/")) if ns.strip("/") else "/"


def _model(client, ns: str):
    from fleetsim.moveit.remote import robot_model

    return robot_model(client, ns)


def error_code_name(code: int) -> str:
    from fleetsim.msgs import moveit_msgs

    for name, _spec, value in moveit_msgs.MoveItErrorCodes.__msgconsts__:
        if value == code:
            return name
    return str(code)


@app.command("list")
def arm_list(
    ns: str = typer.Option("/", "--ns", help="The robot's namespace."),
    connect: str | None = Connect,
) -> None:
    """Planning groups with their joints, and each group's named poses (rad)."""
    with _client(connect) as c:
        model = _model(c, _ns(ns))
    for group in model.group_names:
        joints = model.active_joints(group)
        typer.echo(f"{group}: {', '.join(joints) or '(no joints)'}")
        for pose, values in model.named_targets(group).items():
            typer.echo(f"  {pose}: {' '.join(f'{v:g}' for v in values)}")


@app.command("go")
def arm_go(
    target: str = typer.Argument(..., help="A named pose, or joint values J1,J2,... (rad)."),
    group: str = typer.Option("", "--group", "-g", help="Planning group (default: the first)."),
    ns: str = typer.Option("/", "--ns", help="The robot's namespace."),
    scaling: float = typer.Option(1.0, "--scaling", "-s", help="Velocity/acceleration scaling."),
    timeout: float = typer.Option(120.0, "--timeout", help="Wall seconds to wait for the result."),
    connect: str | None = Connect,
) -> None:
    """Plan and execute a move to TARGET through move_group; prints the result."""
    from fleetsim.moveit.remote import RemoteActionClient
    from fleetsim.msgs import moveit_msgs

    if not 0 < scaling <= 1:
        raise PlanningError(f"--scaling must be in (0, 1], got {scaling}")
    robot_ns = _ns(ns)
    with _client(connect) as c:
        model = _model(c, robot_ns)
        group = group or model.group_names[0]
        joints = model.active_joints(model.check_group(group))
        if "," in target or _is_number(target):
            try:
                values = [float(v) for v in target.split(",")]
            except ValueError:
                raise PlanningError(f"joint values must be numbers: '{target}'") from None
            if len(values) != len(joints):
                raise PlanningError(
                    f"group '{group}' has {len(joints)} joints ({', '.join(joints)}), "
                    f"got {len(values)} values"
                )
            model.check_within_bounds(group, values, "target")
        else:
            values = list(model.named_target(group, target))
        req = moveit_msgs.MotionPlanRequest(
            group_name=group,
            num_planning_attempts=1,
            allowed_planning_time=5.0,
            max_velocity_scaling_factor=scaling,
            max_acceleration_scaling_factor=scaling,
        )
        req.goal_constraints = [
            moveit_msgs.Constraints(
                joint_constraints=[
                    moveit_msgs.JointConstraint(
                        joint_name=j,
                        position=float(v),
                        tolerance_above=1e-4,
                        tolerance_below=1e-4,
                        weight=1.0,
                    )
                    for j, v in zip(joints, values, strict=True)
                ]
            )
        ]
        action = names.join(robot_ns, "move_group")
        client = RemoteActionClient(c, action, moveit_msgs.MoveGroup)
        if not client.wait_for_server():
            raise TransportError(
                f"{action}/goal has no subscriber (is move_group running in {robot_ns}?)"
            )
        handle = client.send_goal(moveit_msgs.MoveGroupGoal(request=req))
        deadline = _wall.monotonic() + timeout
        while handle.result is None:
            if _wall.monotonic() > deadline:
                raise TransportError(f"{action}: no result within {timeout:g} s")
            _wall.sleep(0.02)
        code = handle.result.error_code.val
        typer.echo(f"result: {error_code_name(code)} ({handle.text})")
        if code != moveit_msgs.MoveItErrorCodes.SUCCESS:
            raise PlanningError(f"{action}: {error_code_name(code)}: {handle.text}")


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True
