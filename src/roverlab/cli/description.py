"""``roverlab urdf``: ``check`` (as ``check_urdf``) and ``xacro`` (as the ``xacro`` tool).

Mounted by the root command as ``roverlab urdf``; usable on its own as ``app``::

    roverlab urdf check mybot.xacro --arg laser_visual:=true
    roverlab urdf xacro mybot.xacro laser_visual:=true > mybot.urdf
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from roverlab.description.check import format_check
from roverlab.description.errors import DescriptionError
from roverlab.description.urdf import load_robot, robot_description

__all__ = ["app", "parse_mappings"]

app = typer.Typer(
    help="Check and expand robot descriptions (check_urdf, xacro).",
    no_args_is_help=True,
)


def parse_mappings(items: list[str] | None) -> dict[str, str]:
    """``["name:=value", ...]`` -> ``{"name": "value"}`` (xacro's argument syntax).

    Raises:
        DescriptionError: an item without ``:=``.
    """
    out: dict[str, str] = {}
    for item in items or []:
        name, sep, value = item.partition(":=")
        if not sep or not name.strip():
            raise DescriptionError(f"argument '{item}' is not of the form name:=value")
        out[name.strip()] = value
    return out


def _fail(err: Exception) -> typer.Exit:
    typer.echo(f"error: {err}", err=True)
    return typer.Exit(2)


PackagePathOption = Annotated[
    list[Path] | None,
    typer.Option(
        "--package-path",
        "-p",
        help="Extra folder where $(find pkg) looks for packages (repeatable).",
    ),
]


XacroNsOption = Annotated[
    bool,
    typer.Option(
        "--xacro-ns",
        help="As ROS 1's xacro --xacro-ns: only xacro:-prefixed tags are xacro's "
        "(default: ROS 1's un-prefixed <macro>, <property>, ... and macro calls are "
        "accepted with its deprecation warning).",
    ),
]
MappingsArgument = Annotated[list[str] | None, typer.Argument(help="xacro arguments, name:=value.")]
InorderOption = Annotated[
    bool,
    typer.Option(
        "--inorder",
        "-i",
        help="Accepted for ROS 1 command lines: in-order processing is always on.",
    ),
]


@app.command("check")
def check(
    file: Annotated[Path, typer.Argument(help="A .urdf, .xacro or .urdf.xacro file.")],
    mappings: MappingsArgument = None,
    arg: Annotated[
        list[str] | None,
        typer.Option("--arg", "-a", help="A xacro argument, name:=value (repeatable)."),
    ] = None,
    package_path: PackagePathOption = None,
    xacro_ns: XacroNsOption = False,
    inorder: InorderOption = False,
) -> None:
    """Parse FILE and print its link tree as check_urdf does, then its sensors and plugins."""
    try:
        args = parse_mappings([*(arg or []), *(mappings or [])])
        model = load_robot(file, args=args, package_path=package_path or (), xacro_ns=xacro_ns)
    except DescriptionError as err:
        raise _fail(err) from err
    typer.echo(format_check(model))


@app.command("xacro")
def xacro(
    file: Annotated[Path, typer.Argument(help="The xacro file to expand.")],
    mappings: MappingsArgument = None,
    output: Annotated[
        Path | None, typer.Option("--output", "-o", help="Write to this file, not stdout.")
    ] = None,
    package_path: PackagePathOption = None,
    xacro_ns: XacroNsOption = False,
    inorder: InorderOption = False,
) -> None:
    """Print the URDF that FILE expands to (what `xacro FILE > out.urdf` writes)."""
    try:
        text = robot_description(
            file, parse_mappings(mappings), package_path=package_path or (), xacro_ns=xacro_ns
        )
    except DescriptionError as err:
        raise _fail(err) from err
    if output is None:
        typer.echo(text, nl=False)
    else:
        try:
            output.write_text(text, encoding="utf-8")
        except OSError as err:
            raise _fail(DescriptionError(f"{output}: cannot write: {err.strerror}")) from err
