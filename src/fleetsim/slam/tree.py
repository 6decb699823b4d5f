"""gmapping's trajectory tree: one node per particle per processed scan, sharing the scan.

A node holds its parent, the particle's pose at that scan and the scan (one `ScanRecord` per
processed scan, shared by the nodes of every particle). Nodes no particle descends from are
freed by reference counting, as gmapping's ``TNode`` reference counts do.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class ScanRecord:
    """The beams of one processed scan as the map needs them (laser frame, m and rad)."""

    ranges: np.ndarray  # (B,) beams with 0 < r <= maxRange
    angles: np.ndarray  # (B,)
    laser: np.ndarray  # (3,) laser pose in the base frame


class TreeNode:
    """One particle's pose at one processed scan; ``parent`` is None at the root."""

    __slots__ = ("depth", "parent", "pose", "scan")

    def __init__(self, parent: TreeNode | None, pose: np.ndarray, scan: ScanRecord | None):
        self.parent = parent
        self.pose = np.array(pose, dtype=float)
        self.scan = scan
        self.depth = 0 if parent is None else parent.depth + 1


def common_ancestor(leaves: list[TreeNode]) -> TreeNode | None:
    """The most recent node every leaf descends from (leaves all at the same depth)."""
    nodes = list(leaves)
    while nodes:
        first = nodes[0]
        if all(n is first for n in nodes):
            return first
        if any(n.parent is None for n in nodes):
            return None
        nodes = [n.parent for n in nodes]
    return None


def path_from(ancestor: TreeNode | None, leaf: TreeNode) -> list[TreeNode]:
    """Nodes after ``ancestor`` down to ``leaf``, oldest first (all of them if None)."""
    out = []
    node: TreeNode | None = leaf
    while node is not None and node is not ancestor:
        out.append(node)
        node = node.parent
    out.reverse()
    return out
