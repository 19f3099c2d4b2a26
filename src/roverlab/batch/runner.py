"""Run many seeded episodes, serially in this process or in parallel on Ray.

An episode is a plain function ``fn(config, seed) -> Episode`` defined at module level
(Ray imports it by name in its worker processes). Episode ``i`` of a batch uses seed
``seed + i``; an episode is a deterministic function of its config and seed, so a batch
gives the same per-episode results whatever the number of workers, and the same as the
single command run with that seed.

Ray is an optional dependency (``pip install 'roverlab[ray]'``): ``workers=1`` without an
address runs serially and needs no Ray; anything else starts a local Ray instance with
``workers`` CPUs, or attaches to a running cluster (``address``).
"""

from __future__ import annotations

import importlib
import os
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from roverlab.errors import RoverlabError

__all__ = ["BatchError", "Episode", "EpisodeFn", "episode_stop", "run_batch"]

_STOP = threading.Event()  # the serial batch's stop; never set in a Ray worker


def episode_stop() -> threading.Event:
    """Set when a serial batch is asked to stop (Ctrl-C): a long episode may end early and
    report what it has. (Ray tasks are cancelled instead.)"""
    return _STOP


class BatchError(RoverlabError):
    """A batch could not start (bad arguments, Ray missing or unreachable)."""


@dataclass
class Episode:
    """What one episode returns: a row of plain values (JSON-ready) and its output files
    as bytes (written by the driver, so a cluster needs no shared file system)."""

    row: dict[str, Any]
    files: dict[str, bytes] = field(default_factory=dict)


EpisodeFn = Callable[[dict[str, Any], int], Episode]

# Each episode is single-threaded: one worker per core, no oversubscription.
_ONE_THREAD = {
    "NUMBA_NUM_THREADS": "1",
    "OMP_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
}


def _run_one(fn_path: str, config: dict[str, Any], seed: int, index: int) -> Episode:
    """Episode ``index`` (in a Ray worker or in this process); an exception becomes the
    row's ``error`` (one line), so one failing episode does not end the batch."""
    module, name = fn_path.rsplit(":", 1)
    fn: EpisodeFn = getattr(importlib.import_module(module), name)
    started = time.perf_counter()
    try:
        episode = fn(config, seed)
    except Exception as exc:
        episode = Episode(row={"error": f"{type(exc).__name__}: {exc}".splitlines()[0]})
    episode.row = {"episode": index, "seed": seed, **episode.row}
    episode.row.setdefault("wall_s", round(time.perf_counter() - started, 3))
    return episode


def _fn_path(fn: EpisodeFn) -> str:
    path = f"{fn.__module__}:{fn.__qualname__}"
    if "<" in path:
        raise BatchError(f"an episode function must be defined at module level, not {path}")
    return path


def run_batch(
    fn: EpisodeFn,
    config: dict[str, Any],
    *,
    episodes: int,
    seed: int = 0,
    workers: int = 1,
    address: str | None = None,
    stop: threading.Event | None = None,
    on_done: Callable[[Episode, int, int], None] | None = None,
) -> list[Episode]:
    """Run ``episodes`` episodes of ``fn`` (episode i with seed ``seed + i``) and return
    them in episode order. ``on_done(episode, done, total)`` is called as each finishes;
    setting ``stop`` ends the batch early (running Ray tasks are cancelled) and returns
    the episodes finished so far."""
    if episodes < 1:
        raise BatchError(f"--episodes must be at least 1, got {episodes}")
    if workers < 1:
        raise BatchError(f"--workers must be at least 1, got {workers}")
    path = _fn_path(fn)
    stop = stop or threading.Event()
    seeds = [seed + i for i in range(episodes)]
    if workers == 1 and address is None:
        global _STOP
        _STOP = stop
        done: list[Episode] = []
        for i, s in enumerate(seeds):
            if stop.is_set():
                break
            done.append(_run_one(path, config, s, i))
            if on_done:
                on_done(done[-1], len(done), episodes)
        return done
    return _run_on_ray(path, config, seeds, workers, address, stop, on_done)


def _import_ray() -> Any:
    try:
        return importlib.import_module("ray")
    except ImportError:
        raise BatchError(
            "parallel episodes need Ray, which is not installed: "
            "pip install 'roverlab[ray]' (or run with --workers 1)"
        ) from None


def _run_on_ray(
    path: str,
    config: dict[str, Any],
    seeds: list[int],
    workers: int,
    address: str | None,
    stop: threading.Event,
    on_done: Callable[[Episode, int, int], None] | None,
) -> list[Episode]:
    ray = _import_ray()
    env = {**_ONE_THREAD, "RAY_AUTH_MODE": os.environ.get("RAY_AUTH_MODE", "disabled")}
    os.environ.setdefault("RAY_AUTH_MODE", env["RAY_AUTH_MODE"])
    kwargs: dict[str, Any] = {
        "runtime_env": {"env_vars": env},
        "include_dashboard": False,
        "log_to_driver": False,
        "logging_level": "ERROR",
    }
    try:
        if address is not None:
            ray.init(address=address, **kwargs)
        else:
            ray.init(num_cpus=workers, **kwargs)
    except Exception as exc:
        where = address or "a local instance"
        raise BatchError(f"cannot start Ray ({where}): {str(exc).splitlines()[0]}") from None
    try:
        remote = ray.remote(num_cpus=1, max_retries=0)(_run_one)
        pending = {remote.remote(path, config, s, i): i for i, s in enumerate(seeds)}
        results: dict[int, Episode] = {}
        while pending and not stop.is_set():
            ready, _ = ray.wait(list(pending), num_returns=1, timeout=0.5)
            for ref in ready:
                index = pending.pop(ref)
                results[index] = ray.get(ref)
                if on_done:
                    on_done(results[index], len(results), len(seeds))
        for ref in pending:
            ray.cancel(ref, force=True)
        return [results[i] for i in sorted(results)]
    finally:
        ray.shutdown()
