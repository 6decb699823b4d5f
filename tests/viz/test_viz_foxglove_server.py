"""LiveServer: a real Foxglove WebSocket client subscribes to channels and decodes messages."""

from __future__ import annotations

import asyncio
import json
import struct

import numpy as np
import pytest
import websockets

from fleetsim.errors import TransportError
from fleetsim.msgs import deserialize, sensor_msgs
from fleetsim.runtime import Runtime
from fleetsim.viz.foxglove_server import ROBOTS_TOPIC, LiveServer

#: foxglove-sdk 0.30 speaks the protocol under its new name; older servers use the first
SUBPROTOCOLS = ["foxglove.websocket.v1", "foxglove.sdk.v1"]


async def _advertised(ws, wanted: set[str]) -> dict[str, dict]:
    channels: dict[str, dict] = {}
    while not wanted <= channels.keys():
        msg = await asyncio.wait_for(ws.recv(), 5)
        if isinstance(msg, str):
            data = json.loads(msg)
            if data["op"] == "advertise":
                channels.update({c["topic"]: c for c in data["channels"]})
    return channels


async def _next_message(ws, sub_id: int) -> tuple[int, bytes]:
    while True:
        msg = await asyncio.wait_for(ws.recv(), 5)
        if isinstance(msg, bytes) and msg[0] == 0x01:
            sid, t = struct.unpack_from("<IQ", msg, 1)
            if sid == sub_id:
                return t, msg[13:]


def test_client_subscribes_and_decodes_scan_map_and_robots(room_runtime):
    rt = room_runtime
    server = LiveServer(rt, port=0)

    async def client():
        async with websockets.connect(server.url, subprotocols=SUBPROTOCOLS) as ws:
            info = json.loads(await asyncio.wait_for(ws.recv(), 5))
            assert info["op"] == "serverInfo" and "time" in info["capabilities"]
            ch = await _advertised(ws, {"/robot0/scan", "/map", "/tf", ROBOTS_TOPIC})
            assert ch["/robot0/scan"]["encoding"] == "cdr"
            assert ch["/robot0/scan"]["schemaName"] == "sensor_msgs/msg/LaserScan"
            assert ch["/robot0/scan"]["schemaEncoding"] == "ros2msg"
            assert "float32[] ranges" in ch["/robot0/scan"]["schema"]
            subs = [
                {"id": 1, "channelId": ch["/robot0/scan"]["id"]},
                {"id": 2, "channelId": ch["/map"]["id"]},
                {"id": 3, "channelId": ch[ROBOTS_TOPIC]["id"]},
            ]
            await ws.send(json.dumps({"op": "subscribe", "subscriptions": subs}))
            # the latched map arrives although it was published before anyone subscribed
            _, data = await _next_message(ws, 2)
            grid = deserialize(data, "nav_msgs/msg/OccupancyGrid")
            assert grid.info.width == 200 and grid.data[0] == 100
            await asyncio.sleep(0.2)
            await asyncio.get_running_loop().run_in_executor(None, rt.run, 0.5)
            t, data = await _next_message(ws, 1)
            scan = deserialize(data, sensor_msgs.LaserScan)
            assert scan.header.frame_id == "robot0/base_laser"
            assert t == scan.header.stamp.to_nsec() and t > 0  # log time is sim time
            assert np.isfinite(scan.ranges).sum() > 100
            _, data = await _next_message(ws, 3)
            return data

    try:
        robots = asyncio.run(client())
    finally:
        server.close()
    assert b"robot/robot0" in robots and b"robot0/base_link" in robots


def test_busy_port_is_a_clear_error():
    rt = Runtime()
    first = LiveServer(rt, port=0)
    try:
        with pytest.raises(
            TransportError, match=f"cannot serve Foxglove on ws://127.0.0.1:{first.port}"
        ):
            LiveServer(Runtime(), port=first.port)
    finally:
        first.close()
        first.close()  # idempotent
    assert first._on_graph_event not in rt.graph.listeners
