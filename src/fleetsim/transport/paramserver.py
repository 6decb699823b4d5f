"""The parameter server's remote requests (``fleetsim param ...``, ``fleetsim node run``).

A request is a JSON object ``{"op": "get"|"set"|"list"|"dump"|"delete", "name": "/a/b",
"value": ...}``; the answer is ``{"ok": true, "value": ...}`` or ``{"ok": false, "error": "..."}``.
`answer_param_request` is a pure function of a `ParamTree` and the request bytes, so it runs on
the simulation thread and is tested without a network.
"""

from __future__ import annotations

import json
from typing import Any

from fleetsim.errors import FleetsimError, ParameterError, TransportError
from fleetsim.runtime import names

OPS = ("get", "set", "list", "dump", "delete")


def _jsonable(value: Any) -> Any:
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_jsonable(v) for v in value]
    if hasattr(value, "item") and callable(value.item):  # numpy scalars
        return value.item()
    return value


def _global(name: Any) -> str:
    if not isinstance(name, str) or not name:
        raise ParameterError(f"parameter name must be a non-empty string, got {name!r}")
    full = name if name.startswith("/") else "/" + name
    names.validate_name(full)
    return full


def answer_param_request(tree: Any, request: bytes) -> bytes:
    """Apply one request to ``tree`` (a `ParamTree`); returns the JSON answer."""
    try:
        req = json.loads(request.decode() if request else "{}")
        if not isinstance(req, dict):
            raise ParameterError(f"a parameter request must be a JSON object, got {req!r}")
        op = req.get("op")
        if op not in OPS:
            raise ParameterError(f"unknown parameter operation {op!r}; use one of {', '.join(OPS)}")
        name = _global(req.get("name", "/"))
        if op == "get":
            value: Any = tree.get(name)
        elif op == "dump":
            value = tree.get(name, {}) if name == "/" else tree.get(name)
        elif op == "list":
            prefix = name.rstrip("/")
            value = [n for n in tree.names() if n == prefix or n.startswith(prefix + "/")]
            value = [n for n in value if n != "/"]
        elif op == "set":
            if "value" not in req:
                raise ParameterError(f"set {name}: the request has no 'value'")
            tree.set(name, req["value"])
            value = None
        else:
            tree.delete(name)
            value = None
        return json.dumps({"ok": True, "value": _jsonable(value)}).encode()
    except (FleetsimError, ValueError, TypeError) as e:
        return json.dumps({"ok": False, "error": str(e)}).encode()


def request_param(
    session: Any, keys: Any, op: str, name: str = "/", value: Any = None, timeout: float = 2.0
) -> Any:
    """Send one request to the parameter server over zenoh and return the value."""
    req: dict[str, Any] = {"op": op, "name": name}
    if op == "set":
        req["value"] = value
    for reply in session.get(keys.param, payload=json.dumps(req).encode(), timeout=timeout):
        if reply.ok is not None:
            return parse_param_answer(reply.ok.payload.to_bytes(), f"param {op} {name}")
    raise TransportError(
        f"the parameter server did not answer within {timeout:g} s (is the simulation running, "
        "and not paused?)"
    )


def parse_param_answer(data: bytes, what: str) -> Any:
    """The value of an answer, or the server's error as a `ParameterError`."""
    try:
        ans = json.loads(data.decode())
    except (ValueError, UnicodeDecodeError) as e:
        raise TransportError(f"{what}: the parameter server sent an unreadable answer ({e})") from e
    if not ans.get("ok"):
        raise ParameterError(ans.get("error") or f"{what} failed")
    return ans.get("value")
