"""The main demo: three lizis across the office with amcl, recorded and rendered.

`make demo` runs ``fleetsim demo``: the shipped ``navigation_multi`` scenario with
``localization:=amcl``, headless, until every robot's goal is done (or a time limit), recorded
to ``out/demo.mcap``; then a top-down render to ``out/demo.mp4`` and ``out/demo.png``, and the
results table to ``out/results.txt``.
"""

from __future__ import annotations

from pathlib import Path

from rich.console import Console

#: sim seconds the demo may take at most (the goals are ~25 m away at 0.5 m/s)
DEMO_LIMIT = 150.0


def run_demo(out: str | Path = "out", limit: float = DEMO_LIMIT, progress: bool = True) -> bool:
    """Run the demo; returns True when every robot reached its goal without a collision."""
    from fleetsim.cli.launch import PIPED_WIDTH, print_results, run_launch
    from fleetsim.viz.render import render

    console = Console(stderr=True)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    bag = out / "demo.mcap"
    monitor = run_launch(
        "navigation_multi",
        {"localization": "amcl"},
        duration=limit,
        until_goals=True,
        record=str(bag),
        progress=progress,
    )
    with (out / "results.txt").open("w") as f:
        print_results(monitor, Console(file=f, width=PIPED_WIDTH))
    console.print("rendering the run from above ...")
    render(bag, out / "demo.mp4", fps=10, speed=4.0, progress=progress)
    render(bag, out / "demo.png")
    ok = monitor.success()
    console.print(
        f"[bold]{'all robots reached their goals' if ok else 'not every robot reached its goal'}"
        f"[/]; outputs in {out}/: demo.mcap (open in Foxglove), demo.mp4, demo.png, results.txt"
    )
    return ok
