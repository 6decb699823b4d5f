"""ROS 1 graph resource names: validation, resolution and remapping.

The rules are those of the ROS wiki's *Names* page:

- a name is a sequence of tokens separated by ``/``; each token starts with a letter and holds
  letters, digits and underscores. A name may start with ``/`` (global) or ``~`` (private);
  otherwise it is relative. ``//`` and a ``~`` anywhere but the start are invalid.
- relative names resolve in the node's namespace: ``bar`` in ``/wg`` is ``/wg/bar``;
- private names resolve in the node's own name: ``~bar`` for node ``/wg/node1`` is
  ``/wg/node1/bar``;
- global names resolve to themselves;
- remappings ``from:=to`` are resolved in the node's namespace when they are declared and
  applied to a name after it is resolved.
"""

from __future__ import annotations

import re
from collections.abc import Mapping

from fleetsim.errors import InvalidName

_TOKEN = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")
_REMAP = re.compile(r"\A([^:=\s]+):=(\S*)\Z")


def _check_tokens(body: str, original: str, where: str) -> None:
    for token in body.split("/"):
        if token == "":
            raise InvalidName(
                f"invalid name '{original}'{where}: empty token (a '//' or a trailing '/')"
            )
        if not _TOKEN.match(token):
            bad = next((c for c in token if not (c.isalnum() or c == "_")), token[:1])
            raise InvalidName(
                f"invalid name '{original}'{where}: token '{token}' must start with a letter and "
                f"hold only letters, digits and '_' (offending character '{bad}')"
            )


def validate_name(name: str, where: str = "") -> None:
    """Raise `InvalidName` unless ``name`` is a valid ROS 1 graph resource name.

    ``where`` (for example ``" in robots.launch:12"``) is appended to the message.
    The empty name is valid: it names the enclosing namespace.
    """
    if not isinstance(name, str):
        raise InvalidName(f"invalid name {name!r}{where}: names are strings")
    if name in ("", "/", "~"):
        return
    body = name
    if body.startswith("~"):
        body = body[1:]
        if body.startswith("/"):
            body = body[1:]
    elif body.startswith("/"):
        body = body[1:]
    if "~" in body:
        raise InvalidName(f"invalid name '{name}'{where}: '~' may only start a name")
    _check_tokens(body, name, where)


def validate_namespace(ns: str, where: str = "") -> str:
    """Return ``ns`` as a canonical global namespace (``/a/b``, root ``/``)."""
    if ns in ("", "/"):
        return "/"
    if ns.startswith("~"):
        raise InvalidName(f"invalid namespace '{ns}'{where}: a namespace cannot be private")
    body = ns.strip("/") if ns.endswith("/") else ns.lstrip("/")
    if "~" in body:
        raise InvalidName(f"invalid namespace '{ns}'{where}: '~' may only start a name")
    _check_tokens(body, ns, where)
    return "/" + body


def validate_base_name(name: str, where: str = "") -> None:
    """A node's own name: one token, no namespace."""
    if not name or "/" in name or "~" in name or not _TOKEN.match(name):
        raise InvalidName(
            f"invalid node name '{name}'{where}: a node name is one token (a letter, then letters, "
            "digits or '_'); put namespaces in ns="
        )


def join(ns: str, name: str) -> str:
    """Join a global namespace and a relative name: ``join('/a', 'b/c') == '/a/b/c'``."""
    if not name:
        return ns
    if ns == "/":
        return "/" + name
    return ns + "/" + name


def namespace_of(name: str) -> str:
    """The namespace holding a global name: ``namespace_of('/a/b/c') == '/a/b'``."""
    head = name.rsplit("/", 1)[0]
    return head or "/"


def basename(name: str) -> str:
    return name.rsplit("/", 1)[-1]


def resolve(
    name: str,
    namespace: str = "/",
    node_name: str | None = None,
    remaps: Mapping[str, str] | None = None,
    where: str = "",
) -> str:
    """Resolve ``name`` to a global name as ROS 1 does.

    Parameters
    ----------
    name : the name as written (global, relative or private).
    namespace : the node's global namespace (``/`` for the root).
    node_name : the node's global name, needed for private names.
    remaps : resolved remappings ``{from: to}`` (see `parse_remaps`), applied after resolution.
    where : text appended to error messages to say where the name came from.
    """
    validate_name(name, where)
    ns = validate_namespace(namespace, where)
    if name.startswith("/"):
        resolved = name.rstrip("/") or "/"
    elif name.startswith("~"):
        if node_name is None:
            raise InvalidName(
                f"invalid name '{name}'{where}: a private name ('~') needs a node to resolve "
                "against, and there is none in this context"
            )
        resolved = join(node_name, name[1:].lstrip("/"))
    else:
        resolved = join(ns, name)
    if remaps:
        return remaps.get(resolved, resolved)
    return resolved


def parse_remap(text: str, where: str = "") -> tuple[str, str]:
    """Split ``from:=to`` into its two names, validating both."""
    m = _REMAP.match(text.strip())
    if not m or not m.group(2):
        raise InvalidName(
            f"invalid remap '{text}'{where}: expected 'from:=to', e.g. 'scan:=base_scan'"
        )
    src, dst = m.group(1), m.group(2)
    validate_name(src, where)
    validate_name(dst, where)
    return src, dst


def resolve_remaps(
    remaps: Mapping[str, str] | None,
    namespace: str = "/",
    node_name: str | None = None,
    where: str = "",
) -> dict[str, str]:
    """Resolve both sides of each remap in ``namespace``, as ROS does when a node starts."""
    out: dict[str, str] = {}
    for src, dst in (remaps or {}).items():
        out[resolve(src, namespace, node_name, where=where)] = resolve(
            dst, namespace, node_name, where=where
        )
    return out


def parse_remaps(items: list[str] | tuple[str, ...], where: str = "") -> dict[str, str]:
    """Parse a list of ``from:=to`` strings (command line form) into a dict."""
    return dict(parse_remap(item, where) for item in items)
