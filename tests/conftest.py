"""Suite-wide collection order: the longest scenario runs (``pytest.mark.long``, minutes of wall
time each) go first, so that pytest-xdist's workers start on them and share out the thousands of
short tests afterwards, instead of one worker being handed two of them near the end."""

import pytest


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    items.sort(key=lambda item: item.get_closest_marker("long") is None)  # stable: order kept
