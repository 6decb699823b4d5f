"""A parameter of the wrong type names the file and line it was written on: a rosparam YAML file,
an inline ``<rosparam>`` or a ``<param>`` tag (what the README promises)."""

from dataclasses import dataclass
from pathlib import Path

import pytest

from fleetsim.errors import ParameterError
from fleetsim.launch.xml_frontend import load_xml
from fleetsim.nav.controllers.trajectory_params import TrajectoryPlannerParams
from fleetsim.runtime import Runtime
from fleetsim.runtime.node import Node
from fleetsim.runtime.params import load_params, param

# the lesson's base_local_planner_params.yaml, with one speed limit mistyped
PLANNER_YAML = """\
TrajectoryPlannerROS:
  # Set the velocity limits of the robot
  max_vel_x: "fast"
  min_vel_x: 0.5
  max_rotational_vel: 1.5
  min_in_place_rotational_vel: 1.0
"""


@dataclass(frozen=True)
class _Params:
    rate: float = param(10.0, unit="Hz", range=(0.0, None))
    frame: str = param("map")


class _Probe(Node):
    Params = _Params


def write(tmp_path: Path, body: str, name: str = "t.launch") -> Path:
    p = tmp_path / name
    p.write_text(f"<launch>\n{body}\n</launch>\n")
    return p


def test_rosparam_file_value_of_wrong_type_names_yaml_file_and_line(tmp_path):
    yaml_file = tmp_path / "base_local_planner_params.yaml"
    yaml_file.write_text(PLANNER_YAML)
    p = write(
        tmp_path,
        '<group ns="lizi1">\n'
        '<node pkg="move_base" type="move_base" name="move_base_node">\n'
        '  <rosparam file="$(dirname)/base_local_planner_params.yaml" command="load"/>\n'
        "</node>\n</group>",
    )
    tree = load_xml(p).param_tree()
    assert tree.origin("/lizi1/move_base_node/TrajectoryPlannerROS/max_vel_x") == f"{yaml_file}:3"
    ns = "/lizi1/move_base_node/TrajectoryPlannerROS"
    with pytest.raises(ParameterError) as e:
        load_params(TrajectoryPlannerParams, tree.get(ns), ns)
    assert str(e.value) == (
        f"{ns}: parameter 'max_vel_x' must be float, got str 'fast' (set at {yaml_file}:3)"
    )


def test_node_reading_its_params_names_the_line(tmp_path):
    (tmp_path / "probe.yaml").write_text("# probe\nframe: map\nrate: -5.0\n")
    p = write(
        tmp_path,
        '<node pkg="x" type="y" name="probe">\n  <rosparam file="$(dirname)/probe.yaml"/>\n</node>',
    )
    rt = Runtime()
    load_xml(p).apply_params(rt.params)
    with pytest.raises(ParameterError, match=r"/probe: parameter 'rate' = -5.0 is out of range "
                       rf"\[0, inf\] Hz \(set at {tmp_path}/probe.yaml:3\)"):  # fmt: skip
        _Probe(rt, "probe")


def test_param_tag_and_inline_rosparam_name_the_launch_file_line(tmp_path):
    p = write(
        tmp_path,
        '<node pkg="x" type="y" name="a">\n'
        '  <param name="rate" value="fast"/>\n'
        "</node>\n"
        '<node pkg="x" type="y" name="b">\n'
        "  <rosparam>\n"
        "    frame: map\n"
        "    rate: [1, 2]\n"
        "  </rosparam>\n"
        "</node>\n"
        '<node pkg="x" type="y" name="c">\n'
        '  <rosparam param="frame" subst_value="true">\n'
        "    7\n"
        "  </rosparam>\n"
        "</node>",
    )
    rt = Runtime()
    load_xml(p).apply_params(rt.params)
    with pytest.raises(ParameterError, match=rf"/a: parameter 'rate' must be float, got str "
                       rf"'fast' \(set at {p}:3 <param>\)"):  # fmt: skip
        _Probe(rt, "a")
    with pytest.raises(ParameterError, match=rf"/b: parameter 'rate' must be float, got list "
                       rf"\[1, 2\] \(set at {p}:8\)"):  # fmt: skip
        _Probe(rt, "b")
    with pytest.raises(ParameterError, match=rf"parameter 'frame' must be str, got int 7 "
                       rf"\(set at {p}:13\)"):  # fmt: skip
        _Probe(rt, "c")


def test_origins_follow_overrides_and_deletes():
    rt = Runtime()
    tree = rt.params
    tree.update("/n", {"a": 1, "sub": {"b": 2}}, {"a": "f.yaml:1", "sub/b": "f.yaml:3"})
    assert tree.origin("/n/a") == "f.yaml:1" and tree.origin("/n/sub/b") == "f.yaml:3"
    tree.set("/n/a", "x")  # set from code: no file
    assert tree.origin("/n/a") is None
    tree.set("/n/sub", {"b": "y"}, origin="t.launch:4 <param>")
    assert tree.origin("/n/sub/b") == "t.launch:4 <param>"  # the namespace's origin covers it
    got = tree.get("/n")
    assert got == {"a": "x", "sub": {"b": "y"}}
    assert got.origins == {"sub": "t.launch:4 <param>"}
    assert got["sub"].origins == {"b": "t.launch:4 <param>"}
    tree.delete("/n/sub")
    assert tree.origin("/n/sub/b") is None


def test_param_dicts_dump_as_plain_yaml():
    import yaml

    from fleetsim.runtime.params import ParamTree

    tree = ParamTree()
    tree.update("/", {"a": {"b": 1}}, {"a/b": "f.yaml:2"})
    assert yaml.safe_load(yaml.safe_dump(tree.get("/"))) == {"a": {"b": 1}}
    assert yaml.safe_load(yaml.dump(tree.get("/"))) == {"a": {"b": 1}}


def test_ros2_yaml_launch_param_files_name_the_line_too(tmp_path):
    from fleetsim.launch.yaml_frontend import load_yaml

    (tmp_path / "probe.yaml").write_text(
        "/**:\n  ros__parameters:\n    frame: map\nprobe:\n  ros__parameters:\n    rate: slow\n"
    )
    (tmp_path / "plain.yaml").write_text("rate: 1.0\nframe: 3\n")
    f = tmp_path / "t.launch.yaml"
    f.write_text(
        "launch:\n"
        f"- node: {{pkg: x, exec: y, name: probe, param: [{{from: {tmp_path}/probe.yaml}}]}}\n"
        f"- node: {{pkg: x, exec: y, name: plain, param: [{{from: {tmp_path}/plain.yaml}}]}}\n"
    )
    rt = Runtime()
    load_yaml(f).apply_params(rt.params)
    assert rt.params.origin("/probe/frame") == f"{tmp_path}/probe.yaml:3"
    with pytest.raises(ParameterError, match=rf"'rate' must be float, got str 'slow' \(set at "
                       rf"{tmp_path}/probe.yaml:6\)"):  # fmt: skip
        _Probe(rt, "probe")
    with pytest.raises(ParameterError, match=rf"\(set at {tmp_path}/plain.yaml:2\)"):
        _Probe(rt, "plain")


def test_inline_rosparam_yaml_error_names_the_launch_file_line(tmp_path):
    from fleetsim.errors import LaunchError

    p = write(tmp_path, '<node pkg="x" type="y" name="a">\n  <rosparam>\n    ok: 1\n'
                        "    bad: [1, 2\n  </rosparam>\n</node>")  # fmt: skip
    with pytest.raises(LaunchError, match=rf"{p}:6:\d+: YAML does not parse.*\({p}:3 <rosparam>\)"):
        load_xml(p)


def _tree(tmp_path: Path, yaml_text: str, name: str = "params.yaml", ns: str = ""):
    """The parameter tree of a launch file loading ``yaml_text`` (written to ``name``) into
    /lizi1/move_base_node, or into its namespace ``ns`` under it."""
    (tmp_path / name).write_text(yaml_text)
    attr = f' ns="{ns}"' if ns else ""
    p = write(
        tmp_path,
        '<group ns="lizi1">\n'
        '<node pkg="move_base" type="move_base" name="move_base_node">\n'
        f'  <rosparam file="$(dirname)/{name}" command="load"{attr}/>\n'
        "</node>\n</group>",
    )
    return load_xml(p).param_tree(), tmp_path / name


@pytest.mark.parametrize("planner", ["TrajectoryPlannerROS", "DWAPlannerROS"])
def test_move_base_local_planner_value_of_wrong_type_names_yaml_file_and_line(tmp_path, planner):
    """move_base hands its local planner a copy of the planner's namespace (DWAPlannerROS's
    renamed to TrajectoryPlannerROS's): the copy keeps where each value was set."""
    from fleetsim.nav.move_base_plugins import local_planner_namespace

    key, pkg = "max_vel_x", "base_local_planner"
    if planner == "DWAPlannerROS":
        key, pkg = "max_rot_vel", "dwa_local_planner"
    tree, yaml_file = _tree(tmp_path, f"{planner}:\n  min_vel_x: 0.1\n  {key}: fast\n")
    where = "/lizi1/move_base_node"
    name, raw = local_planner_namespace(f"{pkg}/{planner}", tree.get(where), 10.0, where)
    want = "max_vel_x" if planner == "TrajectoryPlannerROS" else "max_vel_theta"
    with pytest.raises(ParameterError, match=rf"parameter '{want}' must be float, got str "
                       rf"'fast' \(set at {yaml_file}:3\)"):  # fmt: skip
        load_params(TrajectoryPlannerParams, raw, f"{where}/{name}")


def test_an_unknown_planner_parameter_is_warned_about_with_its_file_and_line(tmp_path, caplog):
    from fleetsim.nav.move_base_plugins import local_planner_namespace

    tree, yaml_file = _tree(tmp_path, "TrajectoryPlannerROS:\n  max_vel_X: 0.3\n")
    where = "/lizi1/move_base_node"
    _, raw = local_planner_namespace(
        "base_local_planner/TrajectoryPlannerROS", tree.get(where), 10.0, where
    )
    with caplog.at_level("WARNING"):
        load_params(TrajectoryPlannerParams, raw, where)
    assert (
        f"unknown parameter 'max_vel_X' (did you mean 'max_vel_x'?) (set at {yaml_file}:2)"
        in caplog.text
    )


@pytest.mark.parametrize("form", ["plugins", "pre-Hydro"])
def test_a_costmap_layer_value_of_wrong_type_names_yaml_file_and_line(tmp_path, form):
    """The obstacle layer's observation source, and (without ``plugins``) the pre-Hydro keys
    moved into their layers, keep where each value was set."""
    from fleetsim.nav.costmap.layered_costmap import LayeredCostmap

    if form == "plugins":
        text = (
            "plugins:\n  - {name: obstacle_layer, type: 'costmap_2d::ObstacleLayer'}\n"
            "obstacle_layer:\n  observation_sources: scan\n"
            "  scan: {data_type: LaserScan, marking: maybe}\n"
        )
        line, want = 5, r"parameter 'marking' must be bool, got str 'maybe'"
    else:
        text = "global_frame: odom\nobstacle_range: far\nrolling_window: true\n"
        line, want = 2, r"parameter 'obstacle_range' must be float, got str 'far'"
    tree, yaml_file = _tree(tmp_path, text, "costmap.yaml", ns="local_costmap")
    with pytest.raises(ParameterError, match=rf"{want} \(set at {yaml_file}:{line}\)"):
        LayeredCostmap.from_params(tree.get("/lizi1/move_base_node/local_costmap"), "local")


def test_a_list_a_node_parses_after_loading_names_its_line(tmp_path):
    """aruco_detect's id lists are strings parsed after the parameters load: an id outside the
    dictionary still names the launch file's line."""
    from fleetsim.vision import ArucoDetect

    p = write(
        tmp_path,
        '<node pkg="aruco_detect" type="aruco_detect" name="aruco_detect">\n'
        '  <param name="dictionary" value="0"/>\n'
        '  <param name="ignore_fiducials" value="3-60"/>\n'
        "</node>",
    )
    rt = Runtime()
    load_xml(p).apply_params(rt.params)
    with pytest.raises(ParameterError, match=rf"id 60 in '3-60' is not in the dictionary, whose "
                       rf"ids are 0..49 \(set at {p}:4 <param>\)"):  # fmt: skip
        ArucoDetect(rt)
