"""File helpers shared by the SLAM data modules: line-based text reads, atomic text writes."""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from pathlib import Path

from roverlab import fileio

__all__ = ["atomic_write_text", "finite_floats", "text_rows"]


def text_rows(path: Path, error: type[Exception]) -> Iterator[tuple[int, list[str]]]:
    """``(line number, whitespace-separated fields)`` of each line of a UTF-8 text file;
    blank lines and ``#`` comments are skipped.

    Raises:
        error: the file cannot be read (the message names it).
    """
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise error(f"{path}: cannot read: {err}") from err
    for lineno, line in enumerate(text.splitlines(), start=1):
        parts = line.split()
        if parts and not parts[0].startswith("#"):
            yield lineno, parts


def finite_floats(parts: Sequence[str], where: str, error: type[Exception]) -> list[float]:
    """The fields as finite floats.

    Raises:
        error: ``<where>: not a number: ...`` or ``<where>: non-finite value``.
    """
    try:
        vals = [float(s) for s in parts]
    except ValueError as err:
        raise error(f"{where}: not a number: {err}") from err
    if not all(math.isfinite(v) for v in vals):
        raise error(f"{where}: non-finite value")
    return vals


def atomic_write_text(path: str | Path, text: str, error: type[Exception]) -> None:
    """Write ``text`` (UTF-8, ``\\n`` line ends) to ``path`` through a temporary file
    (:func:`roverlab.fileio.atomic_write_text`), so a reader never sees a half-written file.

    Raises:
        error: the file cannot be written (the message names it).
    """
    p = Path(path)
    try:
        fileio.atomic_write_text(p, text)
    except OSError as err:
        raise error(f"{p}: cannot write: {err.strerror or err}") from err
