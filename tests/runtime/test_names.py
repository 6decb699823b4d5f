"""Name resolution, table-driven from the ROS wiki's Names page, plus properties."""

import pytest
from hypothesis import given
from hypothesis import strategies as st

from fleetsim.errors import InvalidName
from fleetsim.runtime import names

# (node full name, name as written, resolved) -- the wiki's resolution table
RESOLUTION = [
    ("/node1", "bar", "/bar"),
    ("/node1", "/bar", "/bar"),
    ("/node1", "~bar", "/node1/bar"),
    ("/wg/node2", "bar", "/wg/bar"),
    ("/wg/node2", "/bar", "/bar"),
    ("/wg/node2", "~bar", "/wg/node2/bar"),
    ("/wg/node3", "foo/bar", "/wg/foo/bar"),
    ("/wg/node3", "/foo/bar", "/foo/bar"),
    ("/wg/node3", "~foo/bar", "/wg/node3/foo/bar"),
    ("/lizi1/move_base", "cmd_vel", "/lizi1/cmd_vel"),
    ("/lizi1/move_base", "~local_costmap/width", "/lizi1/move_base/local_costmap/width"),
    ("/a/b/c/n", "", "/a/b/c"),
]


@pytest.mark.parametrize(("node", "name", "expected"), RESOLUTION)
def test_resolution_table(node, name, expected):
    assert names.resolve(name, names.namespace_of(node), node) == expected


# (node namespace, remap argument, name as written, resolved) -- the wiki's remapping table
REMAPPING = [
    ("/", "foo:=bar", "foo", "/bar"),
    ("/", "foo:=bar", "/foo", "/bar"),
    ("/baz", "foo:=bar", "foo", "/baz/bar"),
    ("/baz", "foo:=bar", "/baz/foo", "/baz/bar"),
    ("/", "/foo:=bar", "foo", "/bar"),
    ("/", "/foo:=bar", "/foo", "/bar"),
    ("/baz", "/foo:=bar", "/foo", "/baz/bar"),
    ("/baz", "/foo:=/a/b/c/bar", "/foo", "/a/b/c/bar"),
]


@pytest.mark.parametrize(("ns", "remap", "name", "expected"), REMAPPING)
def test_remapping_table(ns, remap, name, expected):
    node = names.join(ns, "n")
    remaps = names.resolve_remaps(names.parse_remaps([remap]), ns, node)
    assert names.resolve(name, ns, node, remaps) == expected


def test_remap_does_not_touch_other_names():
    remaps = names.resolve_remaps({"scan": "base_scan"}, "/lizi1", "/lizi1/amcl")
    assert names.resolve("odom", "/lizi1", "/lizi1/amcl", remaps) == "/lizi1/odom"
    assert names.resolve("scan", "/lizi1", "/lizi1/amcl", remaps) == "/lizi1/base_scan"


@pytest.mark.parametrize(
    ("bad", "match"),
    [
        ("a//b", r"'a//b'.*empty token"),
        ("/a/~b", r"'~' may only start a name"),
        ("1abc", r"token '1abc' must start with a letter"),
        ("a b", r"offending character ' '"),
        ("a-b", r"offending character '-'"),
        ("a/", r"empty token"),
    ],
)
def test_invalid_names_are_named(bad, match):
    with pytest.raises(InvalidName, match=match):
        names.resolve(bad, "/", "/n")


def test_private_name_without_node_is_an_error():
    with pytest.raises(InvalidName, match=r"'~x'.*needs a node"):
        names.resolve("~x", "/ns")


@pytest.mark.parametrize("bad", ["foo", "foo:=", ":=bar", "foo=bar", "a//b:=c"])
def test_bad_remaps(bad):
    with pytest.raises(InvalidName, match="remap|invalid name"):
        names.parse_remap(bad, where=" in cmdline")


def test_error_names_where_it_came_from():
    with pytest.raises(InvalidName, match=r"in robots.launch:12"):
        names.resolve("a//b", "/", where=" in robots.launch:12")


def test_node_base_names():
    names.validate_base_name("amcl")
    for bad in ["a/b", "~a", "", "1a"]:
        with pytest.raises(InvalidName, match="node name"):
            names.validate_base_name(bad)


def test_namespaces_are_canonical():
    assert names.validate_namespace("") == "/"
    assert names.validate_namespace("lizi1") == "/lizi1"
    assert names.validate_namespace("/lizi1/") == "/lizi1"
    with pytest.raises(InvalidName):
        names.validate_namespace("~x")


token = st.from_regex(r"[A-Za-z][A-Za-z0-9_]{0,6}", fullmatch=True)
relative = st.lists(token, min_size=1, max_size=4).map("/".join)
namespace = st.lists(token, min_size=0, max_size=3).map(lambda t: "/" + "/".join(t))


@given(ns=namespace, name=relative)
def test_relative_names_land_in_the_namespace(ns, name):
    out = names.resolve(name, ns, names.join(ns, "node"))
    assert out.startswith(ns.rstrip("/") + "/")
    assert out.endswith("/" + name)
    names.validate_name(out)


@given(ns=namespace, name=relative)
def test_resolving_is_idempotent(ns, name):
    node = names.join(ns, "node")
    once = names.resolve(name, ns, node)
    assert names.resolve(once, "/other", "/other/n") == once


@given(ns=namespace, name=relative)
def test_private_names_land_under_the_node(ns, name):
    node = names.join(ns, "node")
    assert names.resolve("~" + name, ns, node) == node + "/" + name


@given(a=namespace, b=relative)
def test_namespace_of_join_inverts(a, b):
    full = names.join(a, b)
    assert names.join(names.namespace_of(full), names.basename(full)) == full
