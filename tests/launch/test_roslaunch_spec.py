"""roslaunch's XML specification, tag by tag: each place fleetsim read a file differently from
roslaunch (ros_comm's xmlloader.py, loader.py, substitution_args.py) now reads it the same way,
or is an error saying fleetsim does not support it."""

from pathlib import Path

import pytest

from fleetsim.errors import LaunchError
from fleetsim.launch.substitutions import auto_value
from fleetsim.launch.xml_frontend import load_xml
from fleetsim.runtime.params import ParamTree


def write(tmp_path: Path, body: str, name: str = "t.launch") -> Path:
    p = tmp_path / name
    p.write_text(f"<launch>\n{body}\n</launch>\n")
    return p


# -- if / unless ----------------------------------------------------------------------------
def test_skipped_tags_do_not_evaluate_their_other_attributes(tmp_path):
    p = write(
        tmp_path,
        '<arg name="sim" default="false"/>'
        '<param name="a" value="$(find no_such_pkg_a)/x" if="$(arg sim)"/>'
        '<arg name="b" default="$(find no_such_pkg_b)" if="false"/>'
        '<node pkg="p" type="t" name="n" args="$(find no_such_pkg_c)" unless="true"/>'
        '<include file="$(find no_such_pkg_d)/x.launch" if="0"/>'
        '<group if="false" ns="$(find no_such_pkg_e)"/>'
        '<rosparam file="$(find no_such_pkg_f)/x.yaml" unless="1"/>'
        '<param name="kept" value="1" unless="$(arg sim)"/>',
    )
    plan = load_xml(p)
    assert plan.param_tree().names() == ["/kept"] and plan.nodes == []
    assert "b" not in plan.args


# -- <arg> and <include> ---------------------------------------------------------------------
def _inc(tmp_path: Path, body: str) -> Path:
    inc = tmp_path / "inc.launch"
    inc.write_text(f"<launch>{body}</launch>")
    return inc


def test_pass_all_args_ignores_args_the_included_file_does_not_declare(tmp_path):
    _inc(tmp_path, '<arg name="robot"/><param name="r" value="$(arg robot)"/>'
                   '<param name="w" value="$(arg world)"/>')  # fmt: skip
    p = write(
        tmp_path,
        '<arg name="robot" default="lizi1"/><arg name="world" default="willow"/>'
        '<arg name="gui" default="true"/>'
        '<include file="$(dirname)/inc.launch" pass_all_args="true"/>',
    )
    # 'gui' and 'world' are not declared there: ignored; 'world' is still readable (roslaunch
    # keeps every passed arg in the included file's arg dictionary)
    t = load_xml(p, {"robot": "lizi2"}).param_tree()
    assert t.get("/r") == "lizi2" and t.get("/w") == "willow"


def test_pass_all_args_lets_the_file_and_the_include_override(tmp_path):
    _inc(tmp_path, '<arg name="a" value="fixed"/><arg name="b" default="inner"/>'
                   '<param name="a" value="$(arg a)"/><param name="b" value="$(arg b)"/>'
                   '<param name="c" value="$(arg c)"/>')  # fmt: skip
    p = write(
        tmp_path,
        '<arg name="a" default="outer"/><arg name="b" default="outer"/><arg name="c" default="x"/>'
        '<include file="$(dirname)/inc.launch" pass_all_args="true">'
        '<arg name="c" value="from_include"/></include>',
    )
    t = load_xml(p).param_tree()
    assert (t.get("/a"), t.get("/b"), t.get("/c")) == ("fixed", "outer", "from_include")


def test_without_pass_all_args_unused_and_duplicate_args_are_errors(tmp_path):
    _inc(tmp_path, '<arg name="a"/><param name="a" value="$(arg a)"/>')
    p = write(tmp_path, '<include file="$(dirname)/inc.launch"><arg name="a" value="1"/>'
                        '<arg name="z" value="2"/></include>')  # fmt: skip
    with pytest.raises(LaunchError, match=r"unused args \['z'\] passed to the include"):
        load_xml(p)
    q = write(tmp_path, '<include file="$(dirname)/inc.launch"><arg name="a" value="1"/>'
                        '<arg name="a" value="2"/></include>')  # fmt: skip
    with pytest.raises(LaunchError, match=r"t.launch:2 <arg>: arg 'a' is passed twice"):
        load_xml(q)
    r = write(tmp_path, '<include file="$(dirname)/inc.launch"><arg name="a"/></include>')
    with pytest.raises(LaunchError, match=r"<arg name='a'> in an <include> needs value="):
        load_xml(r)
    # default= in an include passes its value, as roslaunch does
    s = write(tmp_path, '<include file="$(dirname)/inc.launch"><arg name="a" default="d"/>'
                        "</include>")  # fmt: skip
    assert load_xml(s).param_tree().get("/a") == "d"


def test_args_declared_in_a_group_are_not_seen_after_it(tmp_path):
    p = write(tmp_path, '<group><arg name="a" default="1"/><param name="in" value="$(arg a)"/>'
                        '</group><param name="out" value="$(arg a)"/>')  # fmt: skip
    with pytest.raises(LaunchError, match=r"t.launch:2 <param> attribute 'value': arg 'a' is "
                                          "not declared"):  # fmt: skip
        load_xml(p)
    q = write(tmp_path, '<group><arg name="a" default="1"/></group><arg name="a" default="2"/>'
                        '<param name="out" value="$(arg a)"/>')  # fmt: skip
    assert load_xml(q).param_tree().get("/out") == 2


def test_include_env_is_only_for_the_included_nodes(tmp_path):
    _inc(tmp_path, '<node pkg="p" type="t" name="inner"/>')
    p = write(tmp_path, '<include file="$(dirname)/inc.launch"><env name="E" value="1"/>'
                        '</include><node pkg="p" type="t" name="after"/>')  # fmt: skip
    inner, after = load_xml(p).nodes
    assert inner.env == {"E": "1"} and after.env == {}


def test_include_clear_params_clears_its_namespace_first(tmp_path):
    _inc(tmp_path, '<param name="x" value="new"/>')
    p = write(tmp_path, '<include ns="r1" clear_params="true" file="$(dirname)/inc.launch"/>')
    tree = ParamTree()
    tree.set("/r1/old", 1)
    load_xml(p).apply_params(tree)
    assert tree.get("/r1") == {"x": "new"}
    q = write(tmp_path, '<include clear_params="true" file="$(dirname)/inc.launch"/>')
    with pytest.raises(LaunchError, match="'ns' attribute must be set in order to use"):
        load_xml(q)


def test_relative_include_paths_are_read_from_the_current_directory(tmp_path, monkeypatch):
    _inc(tmp_path, '<param name="x" value="1"/>')
    (tmp_path / "sub").mkdir()
    p = write(tmp_path / "sub", '<include file="inc.launch"/>')
    monkeypatch.chdir(tmp_path)
    assert load_xml(p).param_tree().get("/x") == 1
    q = write(tmp_path, '<include file="inc.launch"/>', "q.launch")
    monkeypatch.chdir(tmp_path / "sub")
    msg = r"does not exist in the current directory; roslaunch reads relative include paths "
    with pytest.raises(LaunchError, match=msg + r'from there. Write file="\$\(dirname\)/inc'):
        load_xml(q)


# -- booleans, namespaces ----------------------------------------------------------------------
@pytest.mark.parametrize(
    ("body", "match"),
    [
        ('<node pkg="p" type="t" name="n" respawn="1"/>', r"'respawn': invalid bool value '1'"),
        ('<node pkg="p" type="t" name="n" required="yes"/>', r"'required': invalid bool"),
        ('<group ns="a" clear_params="1"/>', r"'clear_params': invalid bool value '1'"),
        ('<rosparam subst_value="1">a: 1</rosparam>', r"'subst_value': invalid bool"),
        (
            '<include file="x" pass_all_args=""/>',
            r"'pass_all_args': a bool value must be non-empty",
        ),
        ('<group ns=""/>', r"<group> attribute 'ns': the 'ns' attribute is empty"),
        ('<node pkg="p" type="t" name="n" ns=""/>', r"the 'ns' attribute is empty"),
        ('<group clear_params="true"/>', r"'ns' attribute must be set in order to use"),
    ],
)
def test_roslaunch_bool_and_namespace_rules(tmp_path, body, match):
    with pytest.raises(LaunchError, match=match):
        load_xml(write(tmp_path, body))


def test_if_unless_accept_1_and_0_as_roslaunch_does(tmp_path):
    p = write(tmp_path, '<param name="a" value="1" if="1"/><param name="b" value="1" if="0"/>'
                        '<param name="c" value="1" unless="FALSE"/>')  # fmt: skip
    assert load_xml(p).param_tree().names() == ["/a", "/c"]


# -- substitution args -------------------------------------------------------------------------
def test_auto_conversion_is_roslaunchs():
    assert auto_value("3") == 3 and auto_value("3.0") == 3.0 and auto_value("1.") == 1.0
    assert auto_value("TRUE") is True and auto_value("false") is False
    # no '.' and not an int: a string, as roslaunch's convert_value(..., 'auto') gives
    for text in ("1e3", "inf", "nan", "1_000", "0x10", "1.2.3"):
        assert auto_value(text) == text


def test_param_value_is_stripped_and_type_is_not_substituted(tmp_path):
    p = write(tmp_path, '<param name="a" value="  5 "/><param name="s" value=" x " type="str"/>')
    t = load_xml(p).param_tree()
    assert t.get("/a") == 5 and t.get("/s") == "x"
    q = write(tmp_path, '<arg name="t" default="int"/><param name="a" value="5" type="$(arg t)"/>')
    with pytest.raises(LaunchError, match=r"unknown param type '\$\(arg t\)'"):
        load_xml(q)


def test_eval_follows_roslaunch(tmp_path):
    p = write(
        tmp_path,
        '<arg name="n" default="3"/><arg name="name" default="lizi"/>'
        '<param name="a" value="$(eval atan2(1, 1) * 4)"/>'
        '<param name="b" value="$(eval len(name) + n)"/>'
        '<param name="c" value="$(eval arg(\'n\') == 3)" type="str"/>'
        '<param name="d" value="$(eval \'lizi\' in name)" type="str"/>',
    )
    t = load_xml(p).param_tree()
    assert t.get("/a") == pytest.approx(3.141592653589793) and t.get("/b") == 7
    assert t.get("/c") == "True" and t.get("/d") == "True"  # str(True), as roslaunch
    q = write(tmp_path, '<param name="a" value="$(eval __import__(\'os\'))"/>')
    with pytest.raises(LaunchError, match="may not contain double underscore"):
        load_xml(q)
    r = write(tmp_path, '<param name="a" value="$(eval nope + 1)"/>')
    with pytest.raises(LaunchError, match=r"name 'nope' is not defined"):
        load_xml(r)


def test_ros2_substitutions_are_not_roslaunch_xml(tmp_path):
    p = write(tmp_path, '<arg name="a" default="1"/><param name="x" value="$(var a)"/>')
    with pytest.raises(LaunchError, match=r"unknown substitution '\$\(var \.\.\.\)'.*roslaunch "
                                          "knows anon, arg, dirname"):  # fmt: skip
        load_xml(p)


# -- <param> ------------------------------------------------------------------------------------
def test_textfile_and_command_values_are_converted_as_roslaunch_does(tmp_path):
    (tmp_path / "n.txt").write_text("42")
    p = write(
        tmp_path,
        '<param name="t" textfile="$(dirname)/n.txt"/>'
        '<param name="s" textfile="$(dirname)/n.txt" type="str"/>'
        '<param name="c" command="echo 2.5"/>'
        '<param name="y" command="echo \'[1, 2]\'" type="yaml"/>',
    )
    t = load_xml(p).param_tree()
    assert t.get("/t") == 42 and t.get("/s") == "42" and t.get("/c") == 2.5
    assert t.get("/y") == [1, 2]


def test_private_params_outside_a_node_go_to_later_nodes_in_scope(tmp_path):
    p = write(
        tmp_path,
        '<node pkg="p" type="t" name="before"/>'
        '<param name="~rate" value="5"/>'
        '<group ns="g"><param name="~frame" value="map"/><node pkg="p" type="t" name="in"/>'
        "</group>"
        '<node pkg="p" type="t" name="after"><param name="rate" value="7"/></node>',
    )
    t = load_xml(p).param_tree()
    assert not t.has("/before/rate") and not t.has("/rate")
    assert t.get("/g/in") == {"rate": 5, "frame": "map"}
    assert t.get("/after") == {"rate": 7}  # the node's own <param> wins; the group's ~frame
    # did not leak out of the group


def test_node_params_win_over_its_rosparams_whatever_the_order(tmp_path):
    p = write(tmp_path, '<node pkg="p" type="t" name="n"><param name="a" value="1"/>'
                        "<rosparam>{a: 2, b: 3}</rosparam></node>")  # fmt: skip
    assert load_xml(p).param_tree().get("/n") == {"a": 1, "b": 3}


# -- <rosparam> -----------------------------------------------------------------------------------
def test_rosparam_ns_names_a_non_mapping_and_angles_load_as_radians(tmp_path):
    p = write(
        tmp_path,
        '<rosparam ns="footprint">[[0.1, 0.1], [-0.1, 0.1]]</rosparam>'
        '<rosparam ns="a" param="yaw">rad(pi/2)</rosparam>'
        "<rosparam>{pitch: deg(90), roll: !degrees 180, z: !radians 2*pi, s: 'deg(1)'}"
        "</rosparam>",
    )
    t = load_xml(p).param_tree()
    assert t.get("/footprint") == [[0.1, 0.1], [-0.1, 0.1]]
    assert t.get("/a/yaw") == pytest.approx(1.5707963)
    assert t.get("/pitch") == pytest.approx(1.5707963) and t.get("/roll") == pytest.approx(3.14159)
    assert t.get("/z") == pytest.approx(6.2831853) and t.get("/s") == "deg(1)"


def test_rosparam_delete_runs_before_params_and_clear_params_before_values(tmp_path):
    p = write(
        tmp_path,
        '<param name="n/keep" value="1"/>'
        '<node pkg="p" type="t" name="n" clear_params="true"/>'
        '<param name="gone" value="2"/><rosparam command="delete" param="gone"/>',
    )
    tree = ParamTree()
    tree.set("/n/old", 0)
    tree.set("/gone", 1)
    load_xml(p).apply_params(tree)
    # roslaunch: rosparam delete (setup), then clear_params, then every value
    assert tree.get("/n") == {"keep": 1} and tree.get("/gone") == 2


def test_rosparam_dump_writes_the_namespace(tmp_path):
    out = tmp_path / "dump.yaml"
    p = write(tmp_path, f'<rosparam command="dump" file="{out}" param="r"/>')
    tree = ParamTree()
    tree.update("/r", {"a": 1}, {"a": "f.yaml:1"})
    load_xml(p).apply_params(tree)
    assert out.read_text() == "a: 1\n"
    q = write(tmp_path, '<rosparam command="delete" file="x.yaml" param="r"/>')
    with pytest.raises(LaunchError, match="'file' attribute is invalid with 'delete'"):
        load_xml(q)


# -- <node>, <test>, <machine>, <env>, <launch>, <master> ------------------------------------
@pytest.mark.parametrize(
    ("body", "match"),
    [
        (
            '<node pkg="p" type="t" name="n" launch-prefix="gdb -ex run --args"/>',
            r"'launch-prefix': fleetsim runs nodes in this process and does not support",
        ),
        ('<node pkg="p" type="t" name="n" output="file"/>', r"output must be one of 'log', 'scr"),
        ('<node pkg="p" type="t" name="n" cwd="here"/>', r"cwd must be one of 'ROS_HOME', 'node'"),
        (
            '<node pkg="p" type="t" name="n" respawn="true" required="true"/>',
            "respawn and required cannot both be set to true",
        ),
        ('<node pkg="p" type="t" name="n" respawn_delay="soon"/>', "invalid float value 'soon'"),
        ('<node pkg="p" type="t" name="n" machine="m"/>', r"unknown machine 'm'"),
        (
            '<machine name="far" address="10.1.2.3"/><node pkg="p" type="t" name="n" '
            'machine="far"/>',
            r"machine 'far' is at 10.1.2.3; fleetsim does not start nodes on other hosts",
        ),
        (
            '<machine name="far" address="robot7" default="true"/><node pkg="p" type="t" '
            'name="n"/>',
            r"machine 'far' is at robot7",
        ),
        ('<machine name="m" address="localhost" ros-root="/opt"/>', "not supported since ROS Fu"),
        ('<machine name="m" address="localhost" default="maybe"/>', "true, false or never"),
        ('<machine name="m" address="localhost" timeout="-1"/>', "'timeout' must be a positive"),
        ('<machine name="m"/>', "missing required attribute 'address'"),
        ('<test pkg="p" type="t" name="x"/>', "missing required attribute 'test-name'"),
        ('<test pkg="p" type="t" test-name="x" time-limit="0"/>', "'time-limit' must be a posi"),
        ('<test pkg="p" type="t" test-name="x" retry="two"/>', "'retry' must be a number"),
        ('<test pkg="p" type="t" test-name="x" respawn="true"/>', "unknown attribute"),
        ('<env name="E"/>', "missing required attribute 'value'"),
    ],
)
def test_process_elements_errors(tmp_path, body, match):
    with pytest.raises(LaunchError, match=match):
        load_xml(write(tmp_path, body))


def test_process_elements_accepted_as_roslaunch_does(tmp_path):
    p = write(
        tmp_path,
        '<master auto="start"/>'
        '<machine name="here" address="localhost" default="true" timeout="5" ssh-port="22"/>'
        '<node pkg="p" type="t" name="n" cwd="node" respawn="TRUE" respawn_delay="2.5" '
        'output="screen" launch-prefix=""/>'
        '<test pkg="p" type="t" test-name="check" time-limit="60" retry="2"/>',
    )
    plan = load_xml(p)
    (node,) = plan.nodes
    assert node.machine == "here" and node.cwd == "node" and node.respawn
    assert node.respawn_delay == 2.5 and node.output == "screen"
    assert any("<test> skipped" in n for n in plan.notes)
    assert any("defunct <master/>" in n for n in plan.notes)


def test_launch_deprecated_attribute_is_reported(tmp_path):
    p = tmp_path / "old.launch"
    p.write_text('<launch deprecated="use new.launch"><param name="a" value="1"/></launch>')
    assert any("DEPRECATED: use new.launch" in n for n in load_xml(p).notes)


def test_find_is_expanded_after_args_as_roslaunch_does(tmp_path):
    p = write(tmp_path, '<arg name="desc"/><param name="d" value="$(arg desc)/urdf"/>')
    t = load_xml(p, {"desc": "$(find lizi)"}).param_tree()
    assert t.get("/d").endswith("robots/lizi/urdf")
