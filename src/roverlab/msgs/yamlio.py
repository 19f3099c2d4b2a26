"""Messages as YAML: printing like ``ros2 topic echo``, parsing like ``ros2 topic pub``.

YAML is read with a safe loader that also takes ``1e-3`` as a float (PyYAML, following YAML
1.1, reads it as a string) and is lenient where ROS is not: ``{linear:{x:0.2}}``, with no
space after the colons, is read as ``{linear: {x: 0.2}}``.
"""

from __future__ import annotations

import re
from typing import Any, Final

import yaml

from roverlab.errors import yaml_reason

from ._store import STORE
from ._values import default_message, from_dict, to_plain
from .errors import MessageYAMLError

__all__ = ["parse_yaml_message", "to_yaml"]

#: Floats written without a dot (``1e-3``, ``-2E+5``) that YAML 1.1 leaves as strings.
_EXTRA_FLOAT: Final = re.compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$")


class _Loader(yaml.SafeLoader):
    """Safe loader that also resolves ``1e-3`` as a float."""


class _Dumper(yaml.SafeDumper):
    """Safe dumper that quotes strings :class:`_Loader` would read as floats."""


for _cls in (_Loader, _Dumper):
    _cls.add_implicit_resolver("tag:yaml.org,2002:float", _EXTRA_FLOAT, list("-+0123456789"))


def to_yaml(msg: Any) -> str:
    """Format a message as block YAML, as ``ros2 topic echo`` prints it.

    Nested messages are indented mappings, arrays ``- x`` items (``[]`` when empty), float32
    values the shortest decimal that reads back as the same float32. The output reads back
    with :func:`parse_yaml_message`.

    Args:
        msg: The message.

    Returns:
        The YAML text, ending in a newline.
    """
    text: str = yaml.dump(
        to_plain(msg, short_float32=True),
        Dumper=_Dumper,
        sort_keys=False,
        default_flow_style=False,
        allow_unicode=True,
        width=100,
    )
    return text


def _space_after_colons(text: str) -> str:
    """Insert a space after each ``:`` outside quotes that is not followed by whitespace."""
    out: list[str] = []
    quote = ""
    for i, char in enumerate(text):
        out.append(char)
        if quote:
            if char == quote:
                quote = ""
        elif char in "'\"":
            quote = char
        elif char == ":" and i + 1 < len(text) and not text[i + 1].isspace():
            out.append(" ")
    return "".join(out)


def _has_colon_keys(data: object) -> bool:
    if isinstance(data, dict):
        return any((isinstance(k, str) and ":" in k) or _has_colon_keys(v) for k, v in data.items())
    if isinstance(data, list):
        return any(_has_colon_keys(v) for v in data)
    return False


def _load(text: str) -> Any:
    return yaml.load(text, Loader=_Loader)


def parse_yaml_message(typename: object, text: str) -> Any:
    """Build a message from YAML text, flow (``{linear: {x: 0.2}}``) or block form.

    Missing fields keep their defaults; an empty text or ``{}`` gives the default message.
    Text with no space after colons (``{linear:{x:0.2}}``) is accepted too.

    Args:
        typename: Type name in any accepted form, rosbags class or factory.
        text: The YAML text.

    Returns:
        The message.

    Raises:
        UnknownTypeError: Unknown type.
        MessageYAMLError: The text is not valid YAML, or not a mapping.
        FieldError: Unknown field, named by dotted path.
        MessageValueError: Wrong kind of value, named by dotted path.
    """
    spec = STORE.spec(typename)
    error: yaml.YAMLError | None = None
    try:
        data = _load(text)
    except yaml.YAMLError as exc:
        data, error = None, exc
    if error is not None or not isinstance(data, dict | None) or _has_colon_keys(data):
        fixed = _space_after_colons(text)
        if fixed != text:
            try:
                retry = _load(fixed)
            except yaml.YAMLError:
                retry = None
            if isinstance(retry, dict) and not _has_colon_keys(retry):
                data, error = retry, None
    if error is not None:
        raise MessageYAMLError(f"invalid YAML for {spec.typename}: {yaml_reason(error)}") from error
    if data is None:
        return default_message(spec)
    if not isinstance(data, dict):
        raise MessageYAMLError(
            f"invalid YAML for {spec.typename}: expected a mapping of fields, "
            f"got {type(data).__name__} {data!r:.40}"
        )
    return from_dict(spec.typename, data)
