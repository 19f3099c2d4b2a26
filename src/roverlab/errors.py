"""Root of roverlab's exception hierarchy.

Every error a user can cause (bad file, bad flag, unknown topic or type) derives from
:class:`RoverlabError`; the CLI turns it into one line on stderr and exit code 2.
"""

from __future__ import annotations

__all__ = ["RoverlabError", "yaml_reason"]


class RoverlabError(Exception):
    """Base class of every roverlab error meant to be shown to a user as one line."""


def yaml_reason(exc: Exception) -> str:
    """A PyYAML error in one line: its problem and where (``line L, column C``); PyYAML's
    own text spans several lines with a drawing of the context."""
    problem = getattr(exc, "problem", None) or (str(exc).splitlines() or ["invalid YAML"])[0]
    mark = getattr(exc, "problem_mark", None)
    where = f" (line {mark.line + 1}, column {mark.column + 1})" if mark is not None else ""
    return f"{problem}{where}"
