"""The lesson's names: lizi as ``$(find lizi_description)/urdf/lizi.urdf`` through ``xacro.py``,
and what a student sees when a package or file name is mistyped."""

from pathlib import Path

import pytest

from fleetsim.description.packages import PackageIndex, similar_names
from fleetsim.description.urdf import load_robot
from fleetsim.errors import DescriptionError, LaunchError
from fleetsim.launch.packages import ASSETS, similar_files
from fleetsim.launch.xml_frontend import load_xml

LESSON_DESCRIPTION = (
    '<param name="robot_description" '
    'command="$(find xacro)/xacro.py $(find lizi_description)/urdf/lizi.urdf"/>'
)


def write(tmp_path: Path, body: str, name: str = "t.launch") -> Path:
    p = tmp_path / name
    p.write_text(f"<launch>\n{body}\n</launch>\n")
    return p


def _strip_comments(urdf: str) -> str:
    from lxml import etree

    root = etree.fromstring(urdf.encode())
    for c in root.xpath("//comment()"):
        if c.getparent() is not None:
            c.getparent().remove(c)
    return etree.tostring(root).decode()


def test_lesson_robot_description_line_gives_lizi(tmp_path):
    p = write(tmp_path, f'<group ns="lizi1">{LESSON_DESCRIPTION}</group>')
    desc = load_xml(p).param_tree().get("/lizi1/robot_description")
    own = (
        load_xml(
            write(
                tmp_path,
                '<param name="d" command="$(find xacro)/xacro $(find lizi)/urdf/lizi.urdf.xacro"/>',
                "own.launch",
            )
        )
        .param_tree()
        .get("/d")
    )
    # the same robot under both names (only the files' leading comments differ)
    assert _strip_comments(desc) == _strip_comments(own)
    assert 'name="skid_steer_drive_controller"' in desc and "base_pose_ground_truth" in desc


def test_lizi_description_package_and_old_name_both_found():
    index = PackageIndex([ASSETS])
    assert (index.find("lizi_description") / "urdf" / "lizi.urdf").is_file()
    assert (index.find("lizi") / "urdf" / "lizi.urdf.xacro").is_file()
    robot = load_robot(index.find("lizi_description") / "urdf" / "lizi.urdf")
    assert robot.name == "lizi"
    assert {"front_left_joint", "rear_right_joint"} <= set(robot.joints)


def test_xacro_args_pass_through_the_lesson_file(tmp_path):
    p = write(
        tmp_path,
        '<param name="d" command="$(find xacro)/xacro.py '
        "$(find lizi_description)/urdf/lizi.urdf laser_pose:='0 0 0.5 0 0 0'\"/>",
    )
    assert "<pose>0 0 0.5 0 0 0</pose>" in load_xml(p).param_tree().get("/d")


def test_misspelled_package_suggests_similar_packages(tmp_path):
    p = write(tmp_path, '<param name="d" value="$(find lizi_descripton)/urdf/lizi.urdf"/>')
    msg = r"t.launch:2 <param> attribute 'value': package 'lizi_descripton' not found \(did "
    with pytest.raises(LaunchError, match=msg + r"you mean 'lizi_description'"):
        load_xml(p)
    # a name that contains a known one is suggested too
    assert "'lizi'" in similar_names("lizi_robot", ["lizi", "jackal", "hunter"])
    assert similar_names("zzz", ["lizi", "jackal"]) == ""
    with pytest.raises(DescriptionError, match=r"did you mean 'turtlebot3_burger'"):
        PackageIndex([ASSETS]).find("turtlebot3_burgr")


def test_missing_file_suggests_similar_files(tmp_path):
    # the xacro name under the lesson's package: suggests the lesson's file
    p = write(
        tmp_path,
        '<param name="d" command="$(find xacro)/xacro $(find lizi_description)/urdf/lizi.xacro"/>',
    )
    msg = r"t.launch:2 <param>: xacro input .*lizi.xacro does not exist; did you mean "
    with pytest.raises(LaunchError, match=msg + r".*urdf/lizi.urdf\?"):
        load_xml(p)
    (tmp_path / "launch").mkdir()
    (tmp_path / "launch" / "one_robot.launch").write_text("<launch/>")
    q = write(tmp_path, '<include file="$(dirname)/launch/one_robt.launch"/>')
    with pytest.raises(
        LaunchError, match=r"does not exist; did you mean .*launch/one_robot.launch"
    ):
        load_xml(q)
    r = write(tmp_path, '<rosparam file="$(dirname)/lanch/x.yaml" command="load"/>')
    with pytest.raises(
        LaunchError, match=r"cannot read rosparam file .*did you mean .*/launch( or|\?)"
    ):
        load_xml(r)


def test_similar_files_lists_a_small_folder_when_nothing_is_close(tmp_path):
    (tmp_path / "a.yaml").write_text("")
    (tmp_path / "b.yaml").write_text("")
    assert similar_files(tmp_path / "zzzz.txt") == f"; {tmp_path} holds a.yaml, b.yaml"
    assert similar_files(tmp_path / "a.yml") == f"; did you mean {tmp_path / 'a.yaml'}?"
