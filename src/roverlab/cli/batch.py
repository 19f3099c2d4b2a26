"""The ``--episodes N --workers K --ray-address`` part shared by ``roverlab explore`` and
``roverlab nav bench``."""

from __future__ import annotations

import threading
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Annotated, Any

import typer

from roverlab.batch import Episode, EpisodeFn, run_batch, write_batch_outputs
from roverlab.cli.common import stop_on_signals

__all__ = [
    "EpisodesOption",
    "RayAddressOption",
    "WorkersOption",
    "absolute",
    "is_batch",
    "run_episodes",
]

# the options every batch-capable command takes (roverlab explore, roverlab nav bench)
EpisodesOption = Annotated[
    int,
    typer.Option(
        "--episodes",
        help="Run this many episodes; episode i uses seed SEED+i. More than one writes "
        "OUT/episodes.json, episodes.csv, episodes.png and OUT/episode_NNN/.",
    ),
]
WorkersOption = Annotated[
    int,
    typer.Option(
        "--workers",
        help="Episodes run in parallel on this many CPUs (a local Ray instance; "
        "needs the 'ray' extra). 1: one after the other, no Ray.",
    ),
]
RayAddressOption = Annotated[
    str | None,
    typer.Option(
        "--ray-address",
        help="Run the episodes on this running Ray cluster (e.g. ray://head:10001 or "
        "auto); see docs/scale.md.",
    ),
]


def is_batch(episodes: int, workers: int, address: str | None) -> bool:
    """Whether the batch options ask for more than the command's single run."""
    return episodes != 1 or workers != 1 or address is not None


def absolute(name_or_path: str) -> str:
    """A bundled name as it is; an existing file as an absolute path (a Ray worker may run
    in another folder, or on another machine with the same files)."""
    path = Path(name_or_path)
    return str(path.resolve()) if path.exists() else name_or_path


def _line(episode: Episode, done: int, total: int) -> str:
    row = episode.row
    if row.get("error"):
        return f"[{done}/{total}] episode {row['episode']} (seed {row['seed']}): {row['error']}"
    shown = ", ".join(
        f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}"
        for k, v in row.items()
        if k not in ("episode", "seed") and isinstance(v, (int, float)) and not isinstance(v, bool)
    )
    return f"[{done}/{total}] episode {row['episode']} (seed {row['seed']}): {shown}"


def run_episodes(
    fn: EpisodeFn,
    config: dict[str, Any],
    *,
    episodes: int,
    seed: int,
    workers: int,
    address: str | None,
    out: Path,
    plot: Sequence[tuple[str, str]],
    title: str,
) -> list[Episode]:
    """Run the batch with a progress line per finished episode (stderr), write its
    outputs, print the aggregate path. Ctrl-C / SIGTERM / SIGHUP: the finished episodes are
    still written (a serial batch lets the running episode end early)."""
    started = time.perf_counter()
    with stop_on_signals(threading.Event()) as stop:
        done = run_batch(
            fn, config, episodes=episodes, seed=seed, workers=workers, address=address,
            stop=stop,
            on_done=lambda e, n, total: typer.echo(_line(e, n, total), err=True),
        )  # fmt: skip
    wall = time.perf_counter() - started
    written = write_batch_outputs(
        out, done, config=config, plot=plot, title=title, wall_s=wall,
        workers=workers,
    )  # fmt: skip
    failed = sum(1 for e in done if e.row.get("error"))
    typer.echo(
        f"batch: {len(done)}/{episodes} episodes in {wall:.1f} s wall on "
        f"{workers} worker(s), {failed} failed; {out / 'episodes.json'}"
    )
    typer.echo(f"wrote {len(written)} files under {out}", err=True)
    return done
