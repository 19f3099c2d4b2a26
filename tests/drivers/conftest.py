"""Fixtures of the driver tests."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from roverlab.core import Context


@pytest.fixture
def contexts() -> Iterator[list[Context]]:
    """Contexts shut down after the test, passed or not (their reader and poll threads
    stop)."""
    made: list[Context] = []
    yield made
    for ctx in made:
        ctx.shutdown()
