"""Errors of the web dashboard."""

from __future__ import annotations

from roverlab.errors import RoverlabError

__all__ = ["DashboardError"]


class DashboardError(RoverlabError):
    """The dashboard cannot start or serve (bad host/port, port in use, bad token)."""
