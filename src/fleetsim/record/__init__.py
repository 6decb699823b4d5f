"""MCAP recording and replay: `Recorder` writes a run, `BagReader` reads it, `Player` replays it."""

from fleetsim.record.player import Player
from fleetsim.record.reader import (
    BagInfo,
    BagMessage,
    BagReader,
    TopicInfo,
    format_info,
    read_messages,
)
from fleetsim.record.writer import Recorder

__all__ = [
    "BagInfo",
    "BagMessage",
    "BagReader",
    "Player",
    "Recorder",
    "TopicInfo",
    "format_info",
    "read_messages",
]
