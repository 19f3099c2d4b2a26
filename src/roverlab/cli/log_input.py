"""What the offline log commands share (``slam run``, ``amcl run``): reading a laser log
with the bag options (:class:`LogSource`), a progress bar over its scans, and
``--param name:=value`` lists."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Annotated, NamedTuple

import typer
import yaml
from rich.console import Console
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)

from roverlab.errors import RoverlabError
from roverlab.slam.data.logs import LaserLog, ScanRecord, load_log
from roverlab.slam.data.reversing import ReversingRepair

__all__ = [
    "BaseFrameOption",
    "FirstOption",
    "LogArgument",
    "LogSource",
    "LoggedOdometryOption",
    "OdomFrameOption",
    "OdomTopicOption",
    "ParamOption",
    "ScanTopicOption",
    "TfTopicOption",
    "parse_params",
    "progress",
]

LogArgument = Annotated[
    Path, typer.Argument(help="CARMEN .clf(.gz/.bz2), ROS 1 .bag, ROS 2 bag or .mcap.")
]
ParamOption = Annotated[
    list[str] | None,
    typer.Option("--param", "-p", help="A method parameter, ROS name:=value (repeatable)."),
]
ScanTopicOption = Annotated[str, typer.Option("--scan-topic", help="Bags: the LaserScan topic.")]
OdomTopicOption = Annotated[
    str,
    typer.Option(
        "--odom-topic",
        help="Bags: the Odometry topic; '' takes odometry from TF (odom frame -> base "
        "frame on --tf-topic).",
    ),
]
TfTopicOption = Annotated[str, typer.Option("--tf-topic", help="Bags: the TF topic.")]
OdomFrameOption = Annotated[
    str, typer.Option("--odom-frame", help="Bags: the odometry frame (TF odometry).")
]
BaseFrameOption = Annotated[
    str | None,
    typer.Option(
        "--base-frame",
        help="Bags: the robot frame (default: the Odometry messages' child frame, or "
        "the TF child of the odometry frame).",
    ),
]
FirstOption = Annotated[
    int | None, typer.Option("--first", help="Use only the first N scans of the log.")
]
LoggedOdometryOption = Annotated[
    bool,
    typer.Option(
        "--logged-odometry",
        help="CARMEN logs: use the odometry poses as logged, without reversing the "
        "steps that went forward while ODOM's velocity was negative.",
    ),
]


def _reversing_note(reversing: ReversingRepair | None) -> str | None:
    """What the odometry repair did, for stderr (None: nothing repaired)."""
    if reversing is None or not reversing.reversed_steps:
        return None
    return (
        f"odometry: {reversing.reversed_steps} of {reversing.steps} steps moved forward "
        "while the velocity was negative (reversing); they were reversed "
        "(--logged-odometry: as logged)"
    )


def progress(records: LaserLog, label: str) -> Iterator[ScanRecord]:
    """The records, with a progress bar on stderr (refreshed only on a terminal)."""
    console = Console(stderr=True)
    if not console.is_terminal:
        yield from records
        return
    with Progress(
        TextColumn(label), BarColumn(), MofNCompleteColumn(), TextColumn("scans"),
        TimeElapsedColumn(), TextColumn("<"), TimeRemainingColumn(), console=console,
        transient=True,
    ) as bar:  # fmt: skip
        task = bar.add_task(label, total=len(records))
        for i, rec in enumerate(records):
            yield rec
            if i % 50 == 49:
                bar.update(task, completed=i + 1)


def parse_params(
    items: list[str] | None, error: Callable[[str], RoverlabError]
) -> dict[str, object]:
    """``name:=value`` items as a dict (values parsed as YAML scalars).

    Raises:
        RoverlabError: (``error(message)``) an item without ``:=`` or a name.
    """
    out: dict[str, object] = {}
    for item in items or []:
        name, sep, value = item.partition(":=")
        if not sep or not name:
            raise error(f"--param expects name:=value, got {item!r}")
        out[name] = yaml.safe_load(value)
    return out


class LogSource(NamedTuple):
    """A log and the options of reading it, as every log command takes them."""

    log: Path
    scan_topic: str
    odom_topic: str
    tf_topic: str
    odom_frame: str
    base_frame: str | None
    first: int | None
    logged_odometry: bool

    def read(self, error: Callable[[str], RoverlabError]) -> tuple[LaserLog, str | None]:
        """Load a CARMEN log or a bag (with the bag options), keeping the ``first`` scans;
        unless ``logged_odometry``, a CARMEN log's steps that went forward while reversing
        are repaired. Also returns :func:`_reversing_note` of the repair.

        Raises:
            LogError: the log cannot be read.
            RoverlabError: (``error(message)``) ``first`` below 2.
        """
        first = self.first
        if first is not None and first < 2:
            raise error(f"--first must be at least 2, got {first}")
        reversing = None if self.logged_odometry else ReversingRepair()
        if self.log.suffix in (".clf", ".gz", ".bz2"):
            records = load_log(self.log, reversing=reversing)
        else:
            records = load_log(
                self.log,
                scan_topic=self.scan_topic,
                odom_topic=self.odom_topic or None,
                tf_topic=self.tf_topic,
                odom_frame=self.odom_frame,
                base_frame=self.base_frame,
            )
        return (records[:first] if first is not None else records), _reversing_note(reversing)
