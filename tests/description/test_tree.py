"""Tests for fleetsim.description.tree: check_urdf text, urdf_to_graphiz source, dot → PDF."""

from __future__ import annotations

import pytest

from fleetsim.description import tree
from fleetsim.description.tree import check_report, graphviz_source, write_graph
from fleetsim.description.urdf import parse_urdf
from fleetsim.errors import DescriptionError

ROBOT = """<robot name="t">
  <link name="base"/><link name="b"/><link name="a"/><link name="c"/>
  <joint name="zj" type="fixed"><origin xyz="1 0.5 0" rpy="0 0 1.5707963"/>
    <parent link="base"/><child link="b"/></joint>
  <joint name="aj" type="fixed"><parent link="base"/><child link="a"/></joint>
  <joint name="cj" type="fixed"><parent link="b"/><child link="c"/></joint>
</robot>"""


def test_check_report_is_depth_first_in_document_order():
    assert check_report(parse_urdf(ROBOT)) == (
        "robot name is: t\n"
        "---------- Successfully Parsed XML ---------------\n"
        "root Link: base has 2 child(ren)\n"
        "    child(1):  b\n"
        "        child(1):  c\n"
        "    child(2):  a\n"
    )


def test_graphviz_source_like_urdf_to_graphiz():
    src = graphviz_source(parse_urdf(ROBOT))
    lines = src.splitlines()
    assert lines[:3] == ["digraph G {", "node [shape=box];", '"base" [label="base"];']
    assert "node [shape=ellipse, color=blue, fontcolor=blue];" in lines
    assert '"base" -> "zj" [label="xyz: 1 0.5 0 \\nrpy: 0 0 1.5708"]' in lines
    assert '"zj" -> "b"' in lines
    assert lines[-1] == "}"


def test_write_graph_makes_gv_and_pdf(tmp_path):
    gv, pdf = write_graph(parse_urdf(ROBOT), tmp_path / "out")
    assert gv.name == "t.gv" and pdf.name == "t.pdf"
    assert pdf.read_bytes().startswith(b"%PDF")


def test_missing_graphviz_is_named(monkeypatch, tmp_path):
    monkeypatch.setattr(tree.shutil, "which", lambda _: None)
    with pytest.raises(DescriptionError, match=r"Graphviz 'dot' was not found.*install graphviz"):
        write_graph(parse_urdf(ROBOT), tmp_path)
