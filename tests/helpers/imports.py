"""Which modules a piece of code imports, measured in a fresh interpreter."""

from __future__ import annotations

import json
import subprocess
import sys


def loaded_after(code: str, modules: tuple[str, ...]) -> list[str]:
    """Run ``code`` in a new Python process; return those of ``modules`` it imported."""
    probe = (
        f"{code}\nimport json, sys\n"
        f"print(json.dumps([m for m in {modules!r} if m in sys.modules]))\n"
    )
    r = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    loaded: list[str] = json.loads(r.stdout.strip().splitlines()[-1])
    return loaded
