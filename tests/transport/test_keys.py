"""Key expressions, wire conventions and session configuration."""

import time

import pytest

from fleetsim.errors import TransportError
from fleetsim.transport.keys import (
    Keys,
    attachment,
    cdr_encoding,
    default_endpoint,
    no_simulation,
    open_session,
    parse_attachment,
    session_config,
    type_of_encoding,
)


def test_keys_follow_resolved_names():
    k = Keys(3)
    assert k.topic("/lizi1/move_base/goal") == "fleetsim/3/topic/lizi1/move_base/goal"
    assert k.topic_name("fleetsim/3/topic/lizi1/scan") == "/lizi1/scan"
    assert k.service("/static_map") == "fleetsim/3/service/static_map"
    assert k.latched("abc", "/map") == "fleetsim/3/latched/abc/map"
    assert k.latched_any("/map") == "fleetsim/3/latched/*/map"
    assert k.graph("z") == "fleetsim/3/graph/z" and k.alive() == "fleetsim/3/alive/*"
    assert k.param == "fleetsim/3/param"
    assert Keys.last_chunk("fleetsim/0/alive/xyz") == "xyz"


def test_domain_from_environment(monkeypatch):
    monkeypatch.setenv("FLEETSIM_DOMAIN", "fleetA")
    assert Keys().root == "fleetsim/fleetA"
    with pytest.raises(TransportError, match=r"zenoh domain 'a/b' is not a valid key chunk"):
        Keys("a/b")


def test_encoding_and_attachment_round_trip():
    enc = cdr_encoding("geometry_msgs/msg/PoseStamped")
    assert type_of_encoding(enc) == "geometry_msgs/msg/PoseStamped"
    assert type_of_encoding("zenoh/bytes") == ""
    assert parse_attachment(attachment("z1", "/lizi1/amcl").decode()) == ("z1", "/lizi1/amcl")
    assert parse_attachment(None) == ("", "")


def test_default_endpoint(monkeypatch):
    monkeypatch.delenv("FLEETSIM_ZENOH", raising=False)
    assert default_endpoint() == "tcp/127.0.0.1:7447"
    monkeypatch.setenv("FLEETSIM_ZENOH", "tcp/10.0.0.5:7447")
    assert default_endpoint() == "tcp/10.0.0.5:7447"


def test_bad_endpoints_and_modes_are_named():
    with pytest.raises(TransportError, match=r"connect endpoint 'localhost:7447' is not a zenoh"):
        session_config("client", connect=["localhost:7447"])
    with pytest.raises(TransportError, match=r"zenoh mode must be 'peer' or 'client', got 'x'"):
        session_config("x")
    with pytest.raises(TransportError, match=r"needs an endpoint to connect to"):
        session_config("client")


def test_client_without_simulation_fails_fast(endpoint):
    t0 = time.monotonic()
    with pytest.raises(TransportError, match=r"^no simulation running at tcp/127\.0\.0\.1:\d+ \("):
        open_session("client", connect=[endpoint])
    assert time.monotonic() - t0 < 2.0
    assert no_simulation("tcp/x:1").startswith("no simulation running at tcp/x:1")


def test_peer_on_a_busy_port_says_so(endpoint):
    first = open_session("peer", listen=[endpoint])
    try:
        with pytest.raises(TransportError, match=r"cannot open a zenoh session listening on"):
            open_session("peer", listen=[endpoint])
    finally:
        first.close()
