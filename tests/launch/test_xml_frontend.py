"""roslaunch XML, element by element, and the lesson's nested multi-robot includes."""

from pathlib import Path

import pytest

from fleetsim.errors import FleetsimError, LaunchError
from fleetsim.launch.xml_frontend import load_xml
from fleetsim.launch.xml_params import convert_value

FIX = Path(__file__).parent / "fixtures" / "multi_pkg"


def write(tmp_path: Path, body: str, name: str = "t.launch") -> Path:
    p = tmp_path / name
    p.write_text(f"<launch>\n{body}\n</launch>\n")
    return p


def test_lesson_includes_give_namespaced_nodes_and_prefixed_frames():
    plan = load_xml(FIX / "launch" / "navigation_multi.launch")
    names = [n.full_name for n in plan.nodes]
    assert names == [
        "/map_server",
        "/lizi1/spawn_lizi_model",
        "/lizi1/robot_state_publisher",
        "/lizi1/link_broadcaster",
        "/lizi1/move_base",
        "/lizi1/fake_localization",
        "/lizi2/spawn_lizi_model",
        "/lizi2/robot_state_publisher",
        "/lizi2/link_broadcaster",
        "/lizi2/move_base",
        "/lizi2/fake_localization",
        "/rviz",
    ]
    tree = plan.param_tree()
    assert tree.get("/use_sim_time") is True
    assert tree.get("/lizi1/tf_prefix") == "lizi1"
    assert tree.get("/lizi2/tf_prefix") == "lizi2"
    assert tree.get("/map_server/frame_id") == "/map"
    gc = tree.get("/lizi2/move_base/global_costmap")
    assert gc["robot_base_frame"] == "lizi2/base_link"
    assert gc["obstacle_range"] == 2.5 and gc["update_frequency"] == 5.0 and gc["static_map"]
    assert tree.get("/lizi1/move_base/local_costmap/scan/topic") == "scan"
    assert tree.get("/lizi2/fake_localization/odom_frame_id") == "lizi2/odom"
    spawn = plan.nodes[1]
    assert spawn.args == ["-x", "20", "-y", "15", "-z", "0", "-urdf", "-param",
                          "/robot_description", "-model", "lizi1"]  # fmt: skip
    assert plan.nodes[4].remaps == {"map": "/map"}
    assert plan.nodes[0].args[0].endswith("maps/office.yaml")


def test_if_unless_switch_nodes():
    plan = load_xml(FIX / "launch" / "one_robot.launch",
                    {"robot_name": "r", "init_pose": "-x 1", "use_amcl": "true"})  # fmt: skip
    types = [n.type for n in plan.nodes]
    assert "amcl" in types and "fake_localization" not in types


def test_args_defaults_values_and_command_line(tmp_path):
    p = write(tmp_path, '<arg name="a" default="1"/><arg name="b" value="$(arg a)x"/>'
                        '<param name="p" value="$(arg b)"/>')  # fmt: skip
    assert load_xml(p).param_tree().get("/p") == "1x"
    assert load_xml(p, {"a": "7"}).param_tree().get("/p") == "7x"
    with pytest.raises(LaunchError, match="arg 'b' has a fixed value"):
        load_xml(p, {"b": "2"})
    with pytest.raises(LaunchError, match=r"unused args \['zz'\] passed on the command line"):
        load_xml(p, {"zz": "1"})


def test_required_arg_missing_names_arg_file_and_line(tmp_path):
    p = write(tmp_path, '<arg name="robot"/>\n<param name="x" value="$(arg robot)"/>')
    with pytest.raises(LaunchError, match=r"t.launch:3 <param> attribute 'value': arg 'robot' "
                                          r"is required but not set"):  # fmt: skip
        load_xml(p)


def test_undeclared_arg_suggests(tmp_path):
    p = write(
        tmp_path, '<arg name="robot_name" default="a"/><param name="x" value="$(arg robot)"/>'
    )
    with pytest.raises(LaunchError, match=r"arg 'robot' is not declared \(did you mean"):
        load_xml(p)


def test_eval_env_optenv_anon_dirname(tmp_path, monkeypatch):
    monkeypatch.setenv("FLEET_TEST_VAR", "hello")
    p = write(
        tmp_path,
        '<arg name="n" default="3"/>'
        '<param name="e" value="$(eval int(n) * 2)"/>'
        '<param name="s" value="$(eval arg(\'n\') == 3)"/>'
        '<param name="v" value="$(env FLEET_TEST_VAR)"/>'
        '<param name="o" value="$(optenv FLEET_NOT_SET fallback)"/>'
        '<param name="a" value="$(anon rviz)"/>'
        '<param name="d" value="$(dirname)/x"/>',
    )
    t = load_xml(p).param_tree()
    assert t.get("/e") == 6 and t.get("/s") is True and t.get("/v") == "hello"
    assert t.get("/o") == "fallback" and t.get("/a").startswith("rviz_")
    assert t.get("/d") == f"{tmp_path.resolve()}/x"


def test_param_types():
    assert convert_value("3", None, "w") == 3
    assert convert_value("3.5", None, "w") == 3.5
    assert convert_value("True", None, "w") is True
    assert convert_value("/map", None, "w") == "/map"
    assert convert_value("3", "str", "w") == "3"
    assert convert_value("[1, 2]", "yaml", "w") == [1, 2]
    with pytest.raises(LaunchError, match="w: value 'x' is not a valid int"):
        convert_value("x", "int", "w")


def test_rosparam_inline_and_param_attr(tmp_path):
    p = write(
        tmp_path,
        '<group ns="r1"><rosparam ns="amcl">{min_particles: 10, laser: {z: 1}}</rosparam>'
        '<rosparam param="list">[1, 2]</rosparam>'
        '<node pkg="amcl" type="amcl" name="amcl"><rosparam>max_particles: 20</rosparam>'
        '<param name="~odom_frame_id" value="odom"/><param name="/global" value="1"/></node>'
        "</group>",
    )
    t = load_xml(p).param_tree()
    # roslaunch joins every <param> name inside a node onto the node's namespace, even '/global'
    assert t.get("/r1/amcl") == {"min_particles": 10, "laser": {"z": 1}, "max_particles": 20,
                                 "odom_frame_id": "odom", "global": 1}  # fmt: skip
    assert t.get("/r1/list") == [1, 2] and not t.has("/global")


def test_xacro_command_param_runs_in_process(tmp_path):
    robot = tmp_path / "r.urdf.xacro"
    robot.write_text(
        '<robot name="bot" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:arg name="n" default="bot"/><link name="base_link"/>'
        '<link name="$(arg n)_link"/><joint name="j" type="fixed"><parent link="base_link"/>'
        '<child link="$(arg n)_link"/></joint></robot>'
    )
    for cmd in (
        f"$(find xacro)/xacro --inorder {robot} n:=lizi",
        f"$(find xacro)/xacro.py {robot}",
    ):
        p = write(tmp_path, f'<param name="robot_description" command="{cmd}"/>')
        desc = load_xml(p).param_tree().get("/robot_description")
        assert "<robot" in desc and "base_link" in desc
    assert 'name="lizi_link"' in load_xml(
        write(tmp_path, f'<param name="d" command="$(find xacro)/xacro {robot} n:=lizi"/>')
    ).param_tree().get("/d")


def test_launch_level_remaps_apply_to_later_nodes(tmp_path):
    p = write(tmp_path, '<node pkg="a" type="b" name="n1"/><remap from="scan" to="base_scan"/>'
                        '<group ns="g"><node pkg="a" type="b" name="n2"/></group>')  # fmt: skip
    plan = load_xml(p)
    assert plan.nodes[0].remaps == {} and plan.nodes[1].remaps == {"scan": "base_scan"}


def test_remaps_and_private_params_in_args_are_read_as_ros_init_does(tmp_path):
    """``map_saver -f x map:=/robot1/map`` as a node's args (a new user's probe: refused as
    an unknown argument): ``from:=to`` remaps, ``_param:=value`` sets ~param (as YAML), the
    special ``__log:=`` is taken out, every <remap> (the group's too) wins over the args, and
    the rest stay arguments."""
    p = write(
        tmp_path,
        '<group><remap from="odom" to="ground_truth"/>'
        '<node pkg="map_server" type="map_saver" name="saver" ns="r1"\n'
        '      args="-f out/map map:=/robot1/map scan:=base_scan odom:=wheel_odom _rate:=2.5 '
        '_frame:=odom __log:=x"><remap from="scan" to="front/scan"/></node></group>'
        '<param name="r1/saver/rate" value="9.0"/>',  # set later in the file: the args win
    )
    plan = load_xml(p)
    (node,) = plan.nodes
    assert node.args == ["-f", "out/map"]
    assert node.remaps == {"map": "/robot1/map", "scan": "front/scan", "odom": "ground_truth"}
    tree = plan.param_tree()
    assert tree.get("/r1/saver/rate") == 2.5 and tree.get("/r1/saver/frame") == "odom"
    for bad, match in (
        ("a//b:=c", r"invalid name 'a//b'"),
        ("map:=", r"invalid remap 'map:='"),
        ("_:=3", r"args '_:=3': the private parameter has no name"),
    ):
        with pytest.raises(FleetsimError, match=match):
            load_xml(write(tmp_path, f'<node pkg="a" type="b" name="c" args="{bad}"/>'))


@pytest.mark.parametrize(
    ("body", "match"),
    [
        (
            '<nod pkg="a" type="b" name="c"/>',
            r"t.launch:2 <nod>: unknown element <nod> \(did you mean 'node'\?\)",
        ),
        ('<node pkg="a" type="b"/>', r"t.launch:2 <node>: missing required attribute 'name'"),
        (
            '<node pkg="a" type="b" name="c" respawnn="true"/>',
            r"attribute 'respawnn'.*unknown attribute",
        ),
        ('<param name="x"/>', r"needs exactly one of value, textfile, binfile, command"),
        ('<param name="x" value="1" if="maybe"/>', r"expected true/false"),
        ('<group ns="a//b"/>', r"invalid name 'a//b'.*<group> attribute 'ns'"),
        (
            '<node pkg="a" type="b" name="c"><remap from="a//b" to="c"/></node>',
            r"invalid name 'a//b'",
        ),
        ("<rosparam>[1, 2]</rosparam>", r"not a mapping; name it with param="),
        ("<rosparam>a: [1, 2</rosparam>", r"YAML does not parse"),
        ('<include file="nope.launch"/>', r"launch file .*nope.launch does not exist"),
        ('<param name="x" value="$(find no_such_pkg_x)"/>', r"package 'no_such_pkg_x' not found"),
        ('<param name="x" value="$(foo bar)"/>', r"unknown substitution"),
    ],
)
def test_errors_name_file_line_and_element(tmp_path, body, match):
    with pytest.raises(FleetsimError, match=match):
        load_xml(write(tmp_path, body))


def test_xml_syntax_error_has_line(tmp_path):
    p = tmp_path / "bad.launch"
    p.write_text("<launch>\n<node pkg='a'\n</launch>\n")
    with pytest.raises(LaunchError, match=r"bad.launch:\d+: XML does not parse"):
        load_xml(p)
    q = tmp_path / "notlaunch.launch"
    q.write_text("<robot/>")
    with pytest.raises(LaunchError, match="root element must be <launch>"):
        load_xml(q)


def test_eval_reads_bare_args_as_roslaunch_does(tmp_path):
    p = write(
        tmp_path,
        '<arg name="nav" default="false"/><arg name="amcl" default="true"/>'
        '<param name="x" value="1" if="$(eval nav or amcl)"/>'
        '<param name="y" value="1" if="$(eval nav and amcl)"/>'
        "<param name=\"z\" value=\"$(eval str(arg('nav')) + '!')\"/>",
    )
    t = load_xml(p).param_tree()
    # arg() converts as roslaunch's auto type does: 'false' -> False, and str(False) is 'False'
    assert t.has("/x") and not t.has("/y") and t.get("/z") == "False!"
