"""The parameter server's tree and who hears about its changes (rosmaster's semantics).

Names are global and canonical. Setting a dictionary replaces the whole namespace under
the key; getting a namespace returns its tree. A node subscribed to a key hears of a
change to that key, to anything under it, and of a parent being replaced so that its key
is gone (value ``{}``); keys in notifications carry rosmaster's trailing slash.
"""

from __future__ import annotations

import copy
from typing import Any

__all__ = ["ParamTree", "Update"]

# (subscriber key as registered, the key the update names, its new value)
Update = tuple[str, str, Any]


def _parts(key: str) -> list[str]:
    return [p for p in key.split("/") if p]


def _join(ns: str, name: str) -> str:
    return ns.rstrip("/") + "/" + name


class ParamTree:
    def __init__(self) -> None:
        self.root: dict[str, Any] = {}

    def get(self, key: str) -> Any:
        """The value (a deep copy for a namespace). Raises KeyError when unset."""
        val: Any = self.root
        for part in _parts(key):
            if not isinstance(val, dict):
                raise KeyError(key)
            val = val[part]
        return copy.deepcopy(val)

    def has(self, key: str) -> bool:
        try:
            self.get(key)
        except KeyError:
            return False
        return True

    def set(self, key: str, value: Any) -> None:
        parts = _parts(key)
        value = copy.deepcopy(value)
        if not parts:
            if not isinstance(value, dict):
                raise TypeError("cannot set the root of the parameter tree to a non-dictionary")
            self.root = value
            return
        d = self.root
        for part in parts[:-1]:
            nxt = d.get(part)
            if not isinstance(nxt, dict):
                nxt = d[part] = {}
            d = nxt
        d[parts[-1]] = value

    def delete(self, key: str) -> None:
        parts = _parts(key)
        if not parts:
            raise KeyError("cannot delete the root of the parameter tree")
        d: Any = self.root
        for part in parts[:-1]:
            if not isinstance(d, dict) or part not in d:
                raise KeyError(key)
            d = d[part]
        if not isinstance(d, dict) or parts[-1] not in d:
            raise KeyError(key)
        del d[parts[-1]]

    def names(self) -> list[str]:
        out: list[str] = []

        def walk(prefix: str, d: dict[str, Any]) -> None:
            for k, v in d.items():
                if isinstance(v, dict):
                    walk(_join(prefix, k), v)
                else:
                    out.append(_join(prefix, k))

        walk("/", self.root)
        return out

    def search(self, caller_id: str, key: str) -> str | None:
        """rosmaster's upward search: the first namespace from the caller's own private
        one up to the root that holds ``key``'s first part; the full key there."""
        if not key or key.startswith("~"):
            raise ValueError(f"invalid key for searchParam: {key!r}")
        if key.startswith("/"):
            return key if self.has(key) else None
        first = _parts(key)[0]
        spaces = _parts(caller_id)
        for i in range(len(spaces), -1, -1):
            ns = "/" + "/".join(spaces[:i])
            if self.has(_join(ns, first)):
                return _join(ns, key.strip("/"))
        return None


def _all_keys(key: str, value: dict[str, Any], out: list[str]) -> list[str]:
    for k, v in value.items():
        sub = _join(key, k) + "/"
        out.append(sub)
        if isinstance(v, dict):
            _all_keys(sub, v, out)
    return out


def compute_updates(subscribed: list[str], key: str, value: Any) -> list[Update]:
    """The notifications a change of ``key`` to ``value`` (``{}``: deleted) causes for the
    subscribed keys (each canonical with a trailing slash)."""
    if key != "/":
        key = key.rstrip("/") + "/"
    all_keys = _all_keys(key, value, []) if isinstance(value, dict) else None
    updates: list[Update] = []
    for sub in subscribed:
        ns_key = sub if sub.endswith("/") else sub + "/"
        if key.startswith(ns_key):
            updates.append((sub, key, value))
        elif all_keys is not None and ns_key.startswith(key) and sub not in all_keys:
            updates.append((sub, sub, {}))
    if all_keys is not None:
        for k in all_keys:
            if k in subscribed:
                val: Any = value
                for part in _parts(k[len(key) :]):
                    val = val[part]
                updates.append((k, k, val))
    return updates
