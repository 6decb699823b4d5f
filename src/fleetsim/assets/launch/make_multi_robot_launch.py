"""Write the multi-robot avoidance scenarios ``swap_corridor.launch``, ``circle.launch`` and
``willow_swap.launch``.

* ``swap_corridor`` (world ``corridor``: 12 m long, 2 m wide, free x 1..13, y 1..3): arg
  ``robots`` 2 or 4. With 2, lizi1 at the west end and lizi2 at the east end exchange places;
  with 4, two robots queue at each end (1.2 m apart) and each goes to the start of its
  counterpart at the other end.
  ``width`` 2.0 (default) or 1.0: world ``corridor_narrow``, the middle 6 m (x 4..10) only
  1.0 m wide, too narrow for two lizis: the deadlock rule makes one back out into a wide end.
* ``circle`` (world ``open_room``): arg ``robots`` 8 or 16 on a circle of 6 m diameter around
  (7, 7), facing its centre; each goes to the antipodal point.
* ``willow_swap`` (world ``willow-full``, the lesson's Willow Garage map, shipped in
  fleetsim_maps): the lesson's three lizis (``robots`` 3) sent through each other's paths,
  lizi1 to lizi3's start, lizi2 to lizi1's, lizi3 to lizi2's.

All take ``model`` (``lizi``, the default; ``pioneer3at``, whose robots are named pioneer1,
pioneer2, ...; ``turtlebot3_burger`` and ``turtlebot3_waffle``, burger1, waffle1, ..., with
turtlebot3_navigation's parameters; ``jackal``, with the BARN jackal's limits; ``mixed``: odd
robots lizis, even ones pioneer3ats, sharing /position_share with their own footprints and limits),
``solo`` (run only the named robot: the reference for makespan and path length), ``planner``
(``collvoid``, default: collvoid_local_planner/CollvoidLocalPlanner with position sharing and a
robots layer; ``trajectory``: plain TrajectoryPlannerROS, the robots unaware of each other),
``localization`` (fake | amcl) and ``start_delay``. Pass criterion (checked by
tests/scenarios/test_multi_robot_scenarios.py and benchmarks/multi_robot.py): every robot reaches
its goal, no contact between robots or with a wall.

Run ``python make_multi_robot_launch.py [OUTDIR]`` to rewrite them (deterministic).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

CORRIDOR_Y = 2.0  # m, the corridor's centre line
CIRCLE_CENTRE = (7.0, 7.0)
CIRCLE_RADIUS = 3.0  # m (a 6 m circle)
#: the lesson's starts (20, 15), (22, 15), (24, 15) at the nearest free cells for a lizi
#: (tests/scenarios/nav_harness.py lesson_starts), lizi1 facing east, the others west
WILLOW_STARTS = ((20.25, 14.95, 0.0), (22.0, 15.0, math.pi), (23.95, 14.95, math.pi))


def swap_corridor_robots(n: int) -> list[tuple[float, float, float, float, float, float]]:
    """(x, y, yaw, goal x, goal y, goal yaw) of lizi1..n for ``robots`` n (2 or 4)."""
    west, east = [2.0, 3.2], [12.0, 10.8]
    out = []
    for k in range(n // 2):
        out.append((west[k], CORRIDOR_Y, 0.0, east[k], CORRIDOR_Y, 0.0))
        out.append((east[k], CORRIDOR_Y, math.pi, west[k], CORRIDOR_Y, math.pi))
    return out


def circle_robots(n: int) -> list[tuple[float, float, float, float, float, float]]:
    """Robots on the circle, each facing the centre and sent to its antipode."""
    cx, cy = CIRCLE_CENTRE
    out = []
    for k in range(n):
        a = 2 * math.pi * k / n
        x, y = cx + CIRCLE_RADIUS * math.cos(a), cy + CIRCLE_RADIUS * math.sin(a)
        heading = math.remainder(a + math.pi, 2 * math.pi)
        out.append((x, y, heading, 2 * cx - x, 2 * cy - y, heading))
    return out


def willow_swap_robots() -> list[tuple[float, float, float, float, float, float]]:
    """The lesson's three starts, moved to the nearest cells a lizi fits in (its own starts,
    (20, 15), (22, 15) and (24, 15), touch the clutter), each sent to the next one's start:
    lizi1 east to lizi3's, lizi2 and lizi3 west to lizi1's and lizi2's."""
    starts = WILLOW_STARTS
    out = []
    for k, (x, y, yaw) in enumerate(starts):
        gx, gy, _ = starts[(k + 2) % 3]
        out.append((x, y, yaw, gx, gy, yaw))
    return out


def _group(k: int, robot: tuple, minimum: int) -> str:
    x, y, yaw, gx, gy, gyaw = (round(v, 4) for v in robot)
    return f"""
  <group ns="$(arg name{k})" if="$(eval int(robots) >= {minimum} and solo in ('', name{k}))">
    <include file="$(find fleetsim_launch)/include/mr_robot.launch">
      <arg name="robot_name" value="$(arg name{k})"/>
      <arg name="model" value="$(arg model{k})"/>
      <arg name="x" value="{x}"/> <arg name="y" value="{y}"/> <arg name="yaw" value="{yaw}"/>
      <arg name="goal_x" value="{gx}"/> <arg name="goal_y" value="{gy}"/>
      <arg name="goal_yaw" value="{gyaw}"/>
      <arg name="planner" value="$(arg planner)"/>
      <arg name="localization" value="$(arg localization)"/>
      <arg name="start_delay" value="$(arg start_delay)"/>
    </include>
  </group>"""


#: robot model -> the prefix of its robots' names (lizi1, pioneer2, ...)
NAME_PREFIXES = {
    "lizi": "lizi",
    "pioneer3at": "pioneer",
    "turtlebot3_burger": "burger",
    "turtlebot3_waffle": "waffle",
    "jackal": "jackal",
}
#: what ``model:=mixed`` gives robot k: lizis odd, pioneer3ats even
MIXED = ("pioneer3at", "lizi")


def _robot_args(n: int) -> str:
    """Per robot k, ``model{k}`` (the scenario's ``model``; with ``mixed``, by k's parity) and
    ``name{k}`` (its model's name prefix and k)."""
    names = repr(NAME_PREFIXES)
    out = []
    for k in range(1, n + 1):
        model = f"$(eval '{MIXED[k % 2]}' if model == 'mixed' else model)"
        out.append(
            f"""  <arg name="model{k}" value="{model}"/>
  <arg name="name{k}" value="$(eval {names}[model{k}] + '{k}')"/>"""
        )
    return "\n".join(out)


def _choices(values) -> str:
    """ROS 2's ``<choice>`` children of an ``<arg>``: any other value is a launch error naming
    the arg and the allowed values (fleetsim's XML frontend; roslaunch ignores them)."""
    return "".join(f'<choice value="{v}"/>' for v in values)


#: swap_corridor's ``width`` arg: corridor width (m) -> world
CORRIDOR_WORLDS = {2.0: "corridor", 1.0: "corridor_narrow"}


def _world_arg(world: str | dict[float, str]) -> str:
    """The ``map`` arg: one world, or one per ``width`` (its choices)."""
    if isinstance(world, str):
        return f"""  <arg name="map" default="$(find fleetsim_maps)/{world}.yaml"/>"""
    widths = sorted(world, reverse=True)
    choice = " else ".join(f"'{world[w]}' if float(width) == {w}" for w in widths[:-1])
    return f"""  <arg name="width" default="{widths[0]}"
       doc="corridor width, m: {" or ".join(f"{w}" for w in widths)} (narrowed for its middle 6 m:
            too narrow for two lizis to pass; one backs out into a wide end)">
    {_choices(widths)}
  </arg>
  <arg name="world" value="$(eval {choice} else '{world[widths[-1]]}')"/>
  <arg name="map" default="$(find fleetsim_maps)/$(arg world).yaml"/>"""


def scenario(name: str, doc: str, world: str | dict, counts: tuple[int, ...], robots: list) -> str:
    groups = "".join(
        _group(k + 1, r, min(c for c in counts if c > k)) for k, r in enumerate(robots)
    )
    return f"""<launch>
  <!-- {doc}
       Written by make_multi_robot_launch.py (see its docstring); pass criterion: every robot
       reaches its goal without touching another robot or a wall. -->
  <master auto="start"/>
  <arg name="robots" default="{counts[0]}" doc="{" or ".join(str(c) for c in counts)} robots">
    {_choices(counts)}
  </arg>
  <arg name="planner" default="collvoid"
       doc="collvoid (ORCA, position sharing) | trajectory (plain TrajectoryPlannerROS)">
    {_choices(("collvoid", "trajectory"))}
  </arg>
  <arg name="localization" default="fake" doc="fake | amcl">
    {_choices(("fake", "amcl"))}
  </arg>
  <arg name="start_delay" default="2.0" doc="sim seconds before the goals go out"/>
  <arg name="solo" default="" doc="run only this robot (e.g. lizi3): its time and path alone"/>
  <arg name="model" default="lizi"
       doc="lizi | pioneer3at | turtlebot3_burger | turtlebot3_waffle | jackal | mixed (odd
            robots lizis, even ones pioneer3ats)">
    {_choices((*NAME_PREFIXES, "mixed"))}
  </arg>
{_robot_args(len(robots))}
{_world_arg(world)}
  <arg name="gui" default="true" doc="open the live view when run with --viz"/>

  <param name="/use_sim_time" value="true"/>
  <node pkg="map_server" type="map_server" name="map_server" args="$(arg map)">
    <param name="frame_id" value="/map"/>
  </node>
  <include file="$(find gazebo_ros)/launch/empty_world.launch">
    <arg name="world_name" value="$(arg map)"/>
    <arg name="gui" value="$(arg gui)"/>
  </include>
{groups}
</launch>
"""


def write(outdir: Path) -> list[Path]:
    files = {
        "swap_corridor.launch": scenario(
            "swap_corridor",
            "Robots exchange the ends of a 12 m long, 2 m wide corridor (robots:=2 or 4;\n"
            "       width:=1.0 narrows its middle 6 m to 1.0 m).",
            CORRIDOR_WORLDS,
            (2, 4),
            swap_corridor_robots(4),
        ),
        "willow_swap.launch": scenario(
            "willow_swap",
            "The lesson's three lizis in the Willow Garage map sent through each other's paths:\n"
            "       lizi1 to lizi3's start, lizi2 to lizi1's, lizi3 to lizi2's.",
            "willow-full",
            (3,),
            willow_swap_robots(),
        ),
        "circle.launch": scenario(
            "circle",
            "Robots on a 6 m circle each drive to the antipodal point (robots:=8 or 16).",
            "open_room",
            (8, 16),
            circle_robots(16)[::2] + circle_robots(16)[1::2],
        ),
    }
    out = []
    for name, text in files.items():
        p = outdir / name
        p.write_text(text)
        out.append(p)
    return out


if __name__ == "__main__":
    target = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parent
    for p in write(target):
        print(p)
