"""Parameter server requests, answered from a ParamTree."""

import json

import numpy as np
import pytest

from fleetsim.errors import ParameterError, TransportError
from fleetsim.runtime import ParamTree
from fleetsim.transport.paramserver import answer_param_request, parse_param_answer


def ask(tree, **req):
    return json.loads(answer_param_request(tree, json.dumps(req).encode()))


@pytest.fixture
def tree():
    t = ParamTree()
    t.set("/lizi1/amcl/min_particles", 100)
    t.set("/lizi1/amcl/laser_model_type", "likelihood_field")
    t.set("/use_sim_time", True)
    return t


def test_get_set_list_dump_delete(tree):
    assert ask(tree, op="get", name="/lizi1/amcl/min_particles") == {"ok": True, "value": 100}
    assert ask(tree, op="get", name="use_sim_time")["value"] is True
    assert ask(tree, op="set", name="/lizi1/amcl/min_particles", value=500)["ok"]
    assert tree.get("/lizi1/amcl/min_particles") == 500
    assert ask(tree, op="list", name="/lizi1")["value"] == [
        "/lizi1/amcl/laser_model_type",
        "/lizi1/amcl/min_particles",
    ]
    assert ask(tree, op="dump", name="/")["value"]["lizi1"]["amcl"]["min_particles"] == 500
    assert ask(tree, op="delete", name="/use_sim_time")["ok"]
    assert not tree.has("/use_sim_time")


def test_numpy_values_become_json(tree):
    tree.set("/arr", [np.float64(1.5), np.int32(2)])
    assert ask(tree, op="get", name="/arr")["value"] == [1.5, 2]


def test_errors_are_answers_not_exceptions(tree):
    ans = ask(tree, op="get", name="/nope")
    assert ans == {"ok": False, "error": "parameter '/nope' is not set"}
    assert "unknown parameter operation 'frob'" in ask(tree, op="frob")["error"]
    assert "has no 'value'" in ask(tree, op="set", name="/x")["error"]
    assert "must be a JSON object" in json.loads(answer_param_request(tree, b"[1]"))["error"]
    assert not json.loads(answer_param_request(tree, b"{nope"))["ok"]


def test_parse_answer():
    assert parse_param_answer(b'{"ok": true, "value": 3}', "get /x") == 3
    with pytest.raises(ParameterError, match="parameter '/x' is not set"):
        parse_param_answer(b'{"ok": false, "error": "parameter \'/x\' is not set"}', "get /x")
    with pytest.raises(TransportError, match="get /x: the parameter server sent an unreadable"):
        parse_param_answer(b"\xff", "get /x")
