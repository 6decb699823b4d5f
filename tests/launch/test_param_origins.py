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
