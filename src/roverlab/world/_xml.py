"""XML parsing that remembers each element's line number (private).

ElementTree drops line numbers; error messages need them, so the tree is built here from
expat events with a side table ``element -> line``.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from xml.parsers import expat

from roverlab.world.errors import WorldError


@dataclass(eq=False)
class XmlDoc:
    """A parsed XML file: its root element and the line each element starts on."""

    path: Path
    root: ET.Element
    lines: dict[int, int] = field(default_factory=dict)

    def line(self, el: ET.Element) -> int:
        return self.lines.get(id(el), 0)

    def where(self, el: ET.Element) -> str:
        """``path:line`` of an element, for error messages."""
        line = self.line(el)
        return f"{self.path}:{line}" if line else str(self.path)


def parse_xml(data: bytes, path: Path) -> XmlDoc:
    """Parse XML bytes; malformed XML raises one-line :class:`WorldError` with the line."""
    builder = ET.TreeBuilder()
    lines: dict[int, int] = {}
    parser = expat.ParserCreate()
    parser.buffer_text = True

    def start(tag: str, attrs: dict[str, str]) -> None:
        el = builder.start(tag, attrs)
        lines[id(el)] = parser.CurrentLineNumber

    def end(tag: str) -> None:
        builder.end(tag)

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = builder.data
    try:
        parser.Parse(data, True)
        root = builder.close()
    except expat.ExpatError as err:
        msg = expat.ErrorString(err.code) if err.code is not None else str(err)
        raise WorldError(
            f"{path}:{err.lineno}: malformed XML: {msg} (column {err.offset + 1})"
        ) from err
    return XmlDoc(path=path, root=root, lines=lines)


def parse_xml_file(path: Path) -> XmlDoc:
    """Read and parse an XML file (see :func:`parse_xml`)."""
    try:
        data = path.read_bytes()
    except OSError as err:
        raise WorldError(f"{path}: cannot read: {err.strerror or err}") from err
    return parse_xml(data, path)
