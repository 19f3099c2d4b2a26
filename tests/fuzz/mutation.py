"""Strategies for the fuzz tests: valid documents with random edits, and the check every
parser must pass (a result, or the project's one clear error)."""

from __future__ import annotations

import contextlib
import re
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, TypeVar

from hypothesis import HealthCheck, settings
from hypothesis import strategies as st

from roverlab.errors import RoverlabError

T = TypeVar("T")

# A fixed, derandomised budget: the same examples on every run, and the suite's time stays
# bounded (each parser test costs a few seconds).
FUZZ = settings(
    max_examples=100,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)

# pieces that tend to break parsers: markup, numbers at the edges, separators
_TOKENS = [
    "<", ">", "/>", "</", '"', "'", "=", "${", "}", "$(", ")", "&", ";", ":", "-", ".", " ",
    "\n", "\t", "0", "-1", "1e308", "-1e308", "nan", "inf", "NaN", "1e-400", "99999999999",
    "[", "]", "{", "}", ",", "#", "\x00", "\u00e9", "\ufffd", "<!--", "-->", "<![CDATA[",
    "xacro:", "true", "false", "", "1 2 3", "0 0 0",
]  # fmt: skip


# a quoted XML attribute value, or a YAML / key-value value after ": "
_VALUE = re.compile(r'="([^"<]*)"|: ([^\n#]*)')
_VALUES = ["0", "-0.5", "1e9", "-1e9", "nan", "inf", "", "a b", "1 2", "1 2 3 4", "$(arg x)",
           "${1/0}", "${undefined}", "package://nowhere/x.stl", "model://nowhere", "[]", "{}",
           "[1, 2", "~", "null", "yes", "0x10"]  # fmt: skip


@st.composite
def mutated(draw: Any, seed: str, max_edits: int = 6) -> str:
    """``seed`` with 1..max_edits edits. Most examples only change values (an XML
    attribute, a YAML value) so the parser gets past the markup; the rest also insert,
    delete or replace spans, duplicate lines and truncate."""
    text = re.sub(r"^\s*<\?xml[^>]*\?>\s*", "", seed)  # its version/encoding are not data
    well_formed = draw(st.integers(0, 9)) < 7  # most examples keep the markup intact
    for _ in range(draw(st.integers(1, max_edits))):
        kind = (
            "value" if well_formed
            else draw(st.sampled_from(["value", "insert", "delete", "replace", "dup", "truncate"]))
        )  # fmt: skip
        n = len(text)
        at = draw(st.integers(0, max(n, 0)))
        values = [m.span(m.lastindex or 1) for m in _VALUE.finditer(text)]
        if kind == "value" and values:
            # keep the markup well formed, change what it says (a number, a name, a flag)
            lo, hi = values[draw(st.integers(0, len(values) - 1))]
            piece = draw(st.sampled_from(_TOKENS[:-2] + _VALUES) | st.text(max_size=6))
            text = text[:lo] + piece.replace('"', "").replace("<", "") + text[hi:]
        elif kind == "insert":
            piece = draw(st.sampled_from(_TOKENS) | st.text(max_size=8))
            text = text[:at] + piece + text[at:]
        elif kind == "delete" and n:
            text = text[:at] + text[at + draw(st.integers(1, 40)) :]
        elif kind == "replace" and n:
            piece = draw(st.sampled_from(_TOKENS))
            text = text[:at] + piece + text[at + draw(st.integers(1, 12)) :]
        elif kind == "dup":
            lines = text.splitlines(keepends=True)
            if lines:
                i = draw(st.integers(0, len(lines) - 1))
                lines.insert(i, lines[i])
                text = "".join(lines)
        elif kind == "truncate":
            text = text[:at]
    return text


def clean(fn: Callable[..., T], *args: Any, name: str | None = None, **kwargs: Any) -> T | None:
    """``fn(*args)``: its result, or None when it raised the project's error, which must
    be one line (naming ``name`` when given). Any other exception fails the test."""
    try:
        return fn(*args, **kwargs)
    except RoverlabError as err:
        text = str(err)
        assert text and "\n" not in text.strip(), f"not one line: {text!r}"
        if name is not None:
            assert name in text, f"the error does not name {name}: {text!r}"
        return None


@contextlib.contextmanager
def in_folder(
    name: str, data: str | bytes, extra: dict[str, bytes] | None = None
) -> Iterator[Path]:
    """``data`` written to ``name`` in a fresh temporary folder (with the ``extra`` files
    beside it), removed when the block ends: every example gets its own folder, and none
    is left behind."""
    with tempfile.TemporaryDirectory(prefix="roverlab-fuzz-") as folder:
        for other, content in (extra or {}).items():
            (Path(folder) / other).write_bytes(content)
        path = Path(folder) / name
        if isinstance(data, str):
            path.write_text(data, encoding="utf-8", errors="surrogatepass")
        else:
            path.write_bytes(data)
        yield path
