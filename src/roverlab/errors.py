"""Root of roverlab's exception hierarchy.

Every error a user can cause (bad file, bad flag, unknown topic or type) derives from
:class:`RoverlabError`; the CLI turns it into one line on stderr and exit code 2.
"""

from __future__ import annotations

__all__ = ["RoverlabError"]


class RoverlabError(Exception):
    """Base class of every roverlab error meant to be shown to a user as one line."""
