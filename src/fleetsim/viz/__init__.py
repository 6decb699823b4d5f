"""Viewing a run: the Foxglove live server (`LiveServer`) and top-down renders (`render`).

Nothing here is imported by the simulation or the navigation stack; viz/ only reads what the
runtime publishes or what a recording holds.
"""

__all__ = ["LiveServer", "render"]


def __getattr__(name: str):  # import matplotlib or foxglove only when asked for
    if name == "LiveServer":
        from fleetsim.viz.foxglove_server import LiveServer

        return LiveServer
    if name == "render":
        from fleetsim.viz.render import render

        return render
    raise AttributeError(name)
