"""The visual servoing benchmark's report: both followers side by side, and a picture of a run.

Imported by ``visual_servoing.py`` (run from this folder).
"""

from __future__ import annotations

import itertools
from pathlib import Path

import cv2
import numpy as np


def picture(rows: list[dict], path: str) -> None:
    """One panel per (patrol, follower) of the first seed: the map, the target's path, the
    follower's path, and the target's positions in the frames in which the marker was seen."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    import fleetsim

    maps = Path(fleetsim.__file__).parent / "assets" / "maps"
    grid = cv2.imread(str(maps / "example_world.pgm"), cv2.IMREAD_GRAYSCALE)
    res, (ox, oy) = 0.05, (-10.0, -10.0)  # example_world.yaml
    extent = (ox, ox + grid.shape[1] * res, oy, oy + grid.shape[0] * res)
    runs = {}
    for r in rows:
        runs.setdefault((r["patrol"], r["follower"]), r)
    patrols = list(dict.fromkeys(k[0] for k in runs))  # in the order they ran
    followers = list(dict.fromkeys(k[1] for k in runs))
    fig, axes = plt.subplots(
        len(patrols),
        len(followers),
        figsize=(5.5 * len(followers), 5.2 * len(patrols)),
        squeeze=False,
    )
    for (i, pat), (j, fol) in itertools.product(enumerate(patrols), enumerate(followers)):
        ax = axes[i, j]
        ax.imshow(grid, cmap="gray", extent=extent, origin="upper", vmin=0, vmax=255)
        r = runs.get((pat, fol))
        if r is not None and len(r["paths"]):
            p = r["paths"]
            seen = p[:, 4] > 0
            ax.plot(p[:, 2], p[:, 3], "-", color="tab:orange", lw=1.2, label="target (karl)")
            ax.plot(p[:, 0], p[:, 1], "-", color="tab:blue", lw=1.2, label="follower")
            ax.plot(p[seen, 2], p[seen, 3], ".", color="tab:green", ms=3, label="marker seen")
            ax.plot(p[~seen, 2], p[~seen, 3], "x", color="tab:red", ms=3, label="not seen")
            ax.plot(*p[0, :2], "o", color="tab:blue")
            ax.plot(*p[0, 2:4], "o", color="tab:orange")
            ax.set_title(
                f"{fol}, {pat} patrol, seed {r['seed']}: seen {r['detected']:.0%}, "
                f"{r['losses']} losses",
                fontsize=9,
            )
        ax.set_xlim(-5.5, 7.5)
        ax.set_ylim(-6.8, 6.2)
        ax.set_aspect("equal")
        ax.legend(loc="lower left", fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    print(f"\npicture: {path}")


def summary(rows: list[dict], columns: list[tuple[str, str]]) -> None:
    """Side by side: per patrol and strategy, each follower's means over the seeds, and the
    predictive follower's losses against follow_marker's."""
    print("\nside by side: mean over seeds (min..max)")
    keys = sorted({(r["patrol"], r["strategy"]) for r in rows})
    names = ["detected", "in_view", "losses", "dist_mean", "dist_p95", "collisions"]
    print("| patrol | exploration | follower | seeds | " + " | ".join(names) + " |")
    print("|---" * (4 + len(names)) + "|")
    for patrol, strategy in keys:
        means = {}
        for follower in sorted({r["follower"] for r in rows}):
            rs = [
                r
                for r in rows
                if (r["patrol"], r["strategy"], r["follower"]) == (patrol, strategy, follower)
            ]
            if not rs:
                continue
            cells = []
            for n, fmt in columns:
                if n not in names:
                    continue
                v = np.array([r[n] for r in rs], float)
                cells.append(
                    f"{fmt.format(v.mean())} ({fmt.format(v.min())}..{fmt.format(v.max())})"
                )
            means[follower] = np.mean([r["losses"] for r in rs])
            print(f"| {patrol} | {strategy} | {follower} | {len(rs)} | " + " | ".join(cells) + " |")
        if "follow_marker" in means and "predictive" in means:
            fm, pr = means["follow_marker"], means["predictive"]
            ratio = f"{fm / pr:.1f}x fewer" if pr > 0 else f"none against {fm:.1f}"
            print(f"|  |  | predictive's losses: {ratio} |")
