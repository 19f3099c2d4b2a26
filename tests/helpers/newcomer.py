"""A newcomer at the keyboard: documented commands typed into tmux terminals, and what they
print judged as a new user would.

:class:`Terminals` runs each command in a tmux window of a private tmux server (a real
terminal: ``teleop`` and coloured output behave as they do for a user), records everything
the window shows, and ends the commands with Ctrl-C, as the user does. :func:`problems`
reads a transcript for what makes a first run look broken: a traceback, or a warning (or
error) said more than a few times a minute.
"""

from __future__ import annotations

import re
import shlex
import shutil
import subprocess
import sys
import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["TMUX", "Terminals", "problems", "repeated_warnings"]

TMUX = shutil.which("tmux")
_ROVERLAB = f"{shlex.quote(sys.executable)} -m roverlab.cli"
_WARNING = re.compile(r"^\s*(\[(WARN|WARNING|ERROR|FATAL)\]|warning:|error:)", re.IGNORECASE)
_STAMP = re.compile(r"^\s*\[(\w+)\] \[[\d.]+\] ")
_NUMBER = re.compile(r"\d+(\.\d+)?")
#: A warning said more often than this in a minute of running is noise to a newcomer.
MAX_PER_MINUTE = 3


@dataclass
class Terminals:
    """tmux windows of one private tmux server (its socket in ``logs``), each logging to
    ``logs/NAME.log``.

    Args:
        logs: folder of the transcripts.
        env: variables set in every terminal (private ports, the daemon's endpoint).
    """

    logs: Path
    env: dict[str, str] = field(default_factory=dict)
    windows: list[str] = field(default_factory=list)

    def _tmux(self, *args: str) -> str:
        assert TMUX is not None
        self.logs.mkdir(parents=True, exist_ok=True)
        done = subprocess.run(
            [TMUX, "-S", str(self.socket), *args], capture_output=True, text=True, timeout=30
        )
        if done.returncode != 0:
            raise RuntimeError(f"tmux {' '.join(args)}: {done.stderr.strip()}")
        return done.stdout

    def open(self, name: str, command: str) -> None:
        """A new terminal ``name`` typing ``command`` (``roverlab ...`` runs this checkout)."""
        exports = " ".join(f"{k}={shlex.quote(v)}" for k, v in self.env.items())
        shell = f"env {exports} bash --norc --noprofile" if exports else "bash --norc"
        if not self.windows:
            self._tmux("new-session", "-d", "-s", "n", "-n", name, "-x", "160", "-y", "50", shell)
            self._tmux("set-option", "-g", "history-limit", "50000")
        else:
            self._tmux("new-window", "-d", "-t", "n:", "-n", name, shell)
        self.windows.append(name)
        log = self.logs / f"{name}.log"
        self._tmux("pipe-pane", "-o", "-t", f"n:{name}", f"cat >> {shlex.quote(str(log))}")
        self.type(name, command)

    def type(self, name: str, command: str) -> None:
        """Type ``command`` and Enter in terminal ``name``."""
        line = re.sub(r"(^|&& )roverlab\b", lambda m: m.group(1) + _ROVERLAB, command)
        self._tmux("send-keys", "-t", f"n:{name}", "-l", line)
        self._tmux("send-keys", "-t", f"n:{name}", "Enter")

    def keys(self, name: str, keys: str) -> None:
        """Press ``keys`` in terminal ``name`` (no Enter): teleop's driving keys."""
        for key in keys:
            self._tmux("send-keys", "-t", f"n:{name}", "-l", key)
            time.sleep(0.3)

    def transcript(self, name: str) -> str:
        path = self.logs / f"{name}.log"
        text = path.read_text(errors="replace") if path.exists() else ""
        return re.sub(r"\x1b\[[0-9;?]*[A-Za-z]|\r", "", text)

    def close(self, grace_s: float = 15.0) -> dict[str, str]:
        """Ctrl-C in every terminal (as the user ends them), then the transcripts."""
        for name in self.windows:
            self._tmux("send-keys", "-t", f"n:{name}", "C-c")
        deadline = time.monotonic() + grace_s
        while time.monotonic() < deadline:
            busy = self._tmux("list-panes", "-s", "-t", "n", "-F", "#{pane_current_command}")
            if all(cmd in ("bash", "") for cmd in busy.split()):
                break
            time.sleep(0.3)
        out = {name: self.transcript(name) for name in self.windows}
        self.kill()
        return out

    def kill(self) -> None:
        if self.windows:
            subprocess.run([TMUX or "tmux", "-S", str(self.socket), "kill-server"], timeout=30)
            self.windows = []
        self.socket.unlink(missing_ok=True)

    @property
    def socket(self) -> Path:
        """The private tmux server's socket (beside the transcripts)."""
        return self.logs / "tmux.sock"


def repeated_warnings(text: str, minutes: float) -> list[str]:
    """Warnings (and errors) said more than :data:`MAX_PER_MINUTE` times a minute; the
    same warning with other numbers in it is the same warning."""
    said: Counter[str] = Counter()
    for line in text.splitlines():
        if _WARNING.match(line):
            said[_NUMBER.sub("N", _STAMP.sub(r"[\1] ", line.strip()))] += 1
    limit = MAX_PER_MINUTE * max(minutes, 1.0)
    return [f"{n}x: {w}" for w, n in said.items() if n > limit]


def problems(transcripts: dict[str, str], minutes: float) -> list[str]:
    """What makes the run look broken, one line each (empty: nothing)."""
    out: list[str] = []
    for name, text in transcripts.items():
        if "Traceback (most recent call last)" in text:
            at = text.index("Traceback (most recent call last)")
            out.append(f"{name}: a traceback: {text[at : at + 600]}")
        out += [f"{name}: said too often: {w}" for w in repeated_warnings(text, minutes)]
    return out
