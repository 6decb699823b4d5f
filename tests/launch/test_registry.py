"""The node registry: every entry imports; unknown nodes list what exists."""

import pytest

from fleetsim.errors import LaunchError
from fleetsim.launch.registry import NODES, register, resolve_node
from fleetsim.runtime import Node


@pytest.mark.parametrize(("pkg", "type_"), sorted(NODES))
def test_every_registered_node_is_a_node_class(pkg, type_):
    cls = resolve_node(pkg, type_)
    assert isinstance(cls, type) and issubclass(cls, Node), (pkg, type_, cls)


def test_user_nodes_by_module_and_class():
    assert resolve_node("anything", "fleetsim.runtime.node:Node") is Node
    assert resolve_node("fleetsim.runtime.node", "Node") is Node


def test_unknown_node_lists_known_ones():
    match = (
        r"x.launch:3: node tf/static_transform_publisherr is unknown "
        r"\(did you mean 'tf/static_transform_publisher'\?\); known nodes: .*robot_state_publisher"
    )
    with pytest.raises(LaunchError, match=match):
        resolve_node("tf", "static_transform_publisherr", "x.launch:3")
    with pytest.raises(LaunchError, match="cannot import module 'no_such_mod'"):
        resolve_node("p", "no_such_mod:Thing")
    with pytest.raises(LaunchError, match=r"module 'fleetsim.runtime.node' has no 'Nod' \(did you"):
        resolve_node("p", "fleetsim.runtime.node:Nod")


def test_register_checks_the_target():
    with pytest.raises(LaunchError, match="must be 'module:Class'"):
        register("a", "b", "just_a_module")


def test_a_user_node_module_beside_the_launch_file_or_in_the_working_directory(
    tmp_path, monkeypatch
):
    """``type="my_teleop:Teleop"`` with my_teleop.py next to the launch file: fleetsim launch
    had failed to import it (fleetsim batch found it in the working directory)."""
    beside, cwd = tmp_path / "launch_dir", tmp_path / "work"
    beside.mkdir()
    cwd.mkdir()
    code = "from fleetsim.runtime import Node\n\nclass Teleop(Node):\n    pass\n"
    (beside / "fs_probe_teleop_a.py").write_text(code)
    (cwd / "fs_probe_teleop_b.py").write_text(code)
    monkeypatch.chdir(cwd)
    monkeypatch.setattr("sys.path", list(__import__("sys").path))
    # a node of an included file: "file:line <node> (included from top:line <include>)"
    where = f"{beside / 'my.launch'}:7 <node> (included from {cwd / 'top.launch'}:2 <include>)"
    assert resolve_node("p", "fs_probe_teleop_a:Teleop", where).__name__ == "Teleop"
    assert resolve_node("p", "fs_probe_teleop_b:Teleop", where).__name__ == "Teleop"
    with pytest.raises(LaunchError, match="beside the launch file and in the working directory"):
        resolve_node("p", "fs_probe_teleop_c:Teleop", where)
