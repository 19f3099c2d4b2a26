"""Callbacks to nodes, one in flight per node (rosmaster's rule): a slow or dead node
delays only its own notifications. Pending notifications of one kind and key collapse to
the newest (a node that missed three publisher lists needs only the last)."""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Callable
from typing import Any

__all__ = ["Notifier"]

Task = Callable[[], Any]


class Notifier:
    def __init__(self, on_error: Callable[[str, BaseException], None] | None = None) -> None:
        self._lock = threading.Lock()
        self._pending: dict[str, OrderedDict[tuple[str, str], Task]] = {}
        self._busy: set[str] = set()
        self._on_error = on_error
        self._closed = False

    def post(self, api: str, kind: str, key: str, task: Task) -> None:
        """Run ``task`` for the node at ``api`` once its earlier tasks are done."""
        with self._lock:
            if self._closed:
                return
            queue = self._pending.setdefault(api, OrderedDict())
            queue.pop((kind, key), None)
            queue[(kind, key)] = task
            if api in self._busy:
                return
            self._busy.add(api)
        threading.Thread(target=self._drain, args=(api,), daemon=True).start()

    def _drain(self, api: str) -> None:
        while True:
            with self._lock:
                queue = self._pending.get(api)
                if not queue or self._closed:
                    self._pending.pop(api, None)
                    self._busy.discard(api)
                    return
                _, task = queue.popitem(last=False)
            try:
                task()
            except Exception as err:  # a node that went away: its problem, not ours
                if self._on_error is not None:
                    self._on_error(api, err)

    def close(self) -> None:
        with self._lock:
            self._closed = True
            self._pending.clear()
