"""roslaunch XML: ``<launch>`` files read into a flat description of nodes and parameters.

Supported as roslaunch does: ``<arg>`` (default/value, command-line ``name:=value``),
``<param>`` (value/type, ``command=``, ``textfile=``, ``binfile=``), ``<rosparam>``
(``command="load" file=``, inline YAML, ``ns``/``param``), ``<node>`` (pkg, type, name, args,
ns, output, respawn, required, and its ``<param>``/``<rosparam>``/``<remap>`` children),
``<include file=...>`` with ``<arg>`` children and ``ns``, ``<group ns=...>``, top-level
``<remap>``, ``<env>``, ``if=``/``unless=`` on every element, and the substitutions
``$(find pkg)``, ``$(arg name)``, ``$(env VAR)``, ``$(optenv VAR default)``,
``$(anon name)``, ``$(dirname)`` and ``$(eval expr)``. ``<machine>``, ``<test>`` and
``<master>`` are ignored. Every error names the file and the element.
"""

from __future__ import annotations

import math
import os
import re
import shlex
import subprocess
import xml.etree.ElementTree as ET
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from roverlab.description import find_package, robot_description
from roverlab.description.errors import DescriptionError
from roverlab.errors import RoverlabError

__all__ = ["LaunchError", "LaunchSpec", "NodeSpec", "load_launch"]


class LaunchError(RoverlabError):
    """A launch file could not be read or run."""


@dataclass
class NodeSpec:
    """One ``<node>``: what to run, with its private parameters and remappings."""

    pkg: str
    type: str
    name: str
    namespace: str = "/"
    args: str = ""
    params: dict[str, Any] = field(default_factory=dict)
    remaps: dict[str, str] = field(default_factory=dict)
    source: str = ""
    output: str = "log"  # roslaunch's default: INFO to the node's log file, WARN+ to screen
    respawn: bool = False
    respawn_delay: float = 0.0  # wall seconds
    required: bool = False
    env: dict[str, str] = field(default_factory=dict)  # <env> of its scope
    clear_params: bool = False

    @property
    def fq_name(self) -> str:
        return self.namespace.rstrip("/") + "/" + self.name


@dataclass
class LaunchSpec:
    """Everything a launch file (with its includes) asks for."""

    nodes: list[NodeSpec] = field(default_factory=list)
    params: dict[str, Any] = field(default_factory=dict)  # global (absolute) names
    files: list[Path] = field(default_factory=list)


_SUBST = re.compile(r"\$\((\w+)((?:\s+[^()]*)?)\)")
_TRUE = {"true", "1"}
_FALSE = {"false", "0"}


class _Scope:
    """Arguments and namespace of one file (or group)."""

    def __init__(
        self,
        path: Path,
        args: dict[str, str],
        ns: str,
        remaps: dict[str, str],
        env: dict[str, str] | None = None,
    ) -> None:
        self.path = path
        self.args = args
        self.ns = ns
        self.remaps = remaps
        self.env = dict(env or {})  # <env> of this scope: for the nodes declared after it
        self.anon: dict[str, str] = {}


def _where(scope: _Scope, elem: ET.Element) -> str:
    name = elem.get("name")
    return f"{scope.path}: <{elem.tag}" + (f' name="{name}"' if name else "") + ">"


class _Reader:
    def __init__(self, package_path: tuple[str, ...]) -> None:
        self.package_path = package_path
        self.spec = LaunchSpec()
        self._anon_counter = 0

    # ------------------------------------------------------------- substitutions
    def subst(self, text: str, scope: _Scope, elem: ET.Element) -> str:
        if "$(eval " in text:
            expr = text.strip()
            if not (expr.startswith("$(eval ") and expr.endswith(")")):
                raise LaunchError(f"{_where(scope, elem)}: $(eval) must be the whole value")
            return self._eval(expr[7:-1], scope, elem)

        def repl(m: re.Match[str]) -> str:
            verb, rest = m.group(1), m.group(2).strip()
            try:
                if verb == "find":
                    return str(find_package(rest, self.package_path))
                if verb == "arg":
                    if rest not in scope.args:
                        raise LaunchError(f"{_where(scope, elem)}: arg '{rest}' is not set")
                    return scope.args[rest]
                if verb == "env":
                    if rest not in os.environ:
                        raise LaunchError(
                            f"{_where(scope, elem)}: environment variable {rest} is not set"
                        )
                    return os.environ[rest]
                if verb == "optenv":
                    name, _, default = rest.partition(" ")
                    return os.environ.get(name, default)
                if verb == "anon":
                    if rest not in scope.anon:
                        self._anon_counter += 1
                        scope.anon[rest] = f"{rest}_{os.getpid()}_{self._anon_counter}"
                    return scope.anon[rest]
                if verb == "dirname":
                    return str(scope.path.parent)
            except DescriptionError as err:
                raise LaunchError(f"{_where(scope, elem)}: {err}") from err
            raise LaunchError(f"{_where(scope, elem)}: unknown substitution $({verb})")

        prev = None
        out = text
        while prev != out and "$(" in out:
            prev = out
            out = _SUBST.sub(repl, out)
        return out

    def _eval(self, expr: str, scope: _Scope, elem: ET.Element) -> str:
        env: dict[str, Any] = {
            "true": True,
            "false": False,
            "True": True,
            "False": False,
            "pi": math.pi,
            "arg": lambda n: _typed(scope.args[n]),
            "env": lambda n: os.environ[n],
            "optenv": lambda n, d="": os.environ.get(n, d),
            "find": lambda p: str(find_package(p, self.package_path)),
            "dirname": lambda: str(scope.path.parent),
        }
        env.update({k: _typed(v) for k, v in scope.args.items() if k.isidentifier()})
        try:
            value = eval(expr, {"__builtins__": {}, "math": math}, env)
        except Exception as err:
            raise LaunchError(f"{_where(scope, elem)}: $(eval {expr}) failed: {err}") from err
        return str(value).lower() if isinstance(value, bool) else str(value)

    def attr(self, elem: ET.Element, name: str, scope: _Scope, default: str | None = None) -> str:
        raw = elem.get(name)
        if raw is None:
            if default is None:
                raise LaunchError(f"{_where(scope, elem)}: missing attribute '{name}'")
            return default
        return self.subst(raw, scope, elem)

    def enabled(self, elem: ET.Element, scope: _Scope) -> bool:
        for key, want in (("if", True), ("unless", False)):
            if key in elem.attrib:
                value = self.attr(elem, key, scope).strip().lower()
                if value not in _TRUE | _FALSE:
                    raise LaunchError(
                        f"{_where(scope, elem)}: {key}= needs true/false/1/0, got {value!r}"
                    )
                if (value in _TRUE) != want:
                    return False
        return True

    # ------------------------------------------------------------- files
    def read_file(
        self,
        path: Path,
        args: Mapping[str, str],
        ns: str = "/",
        remaps: dict[str, str] | None = None,
        env: dict[str, str] | None = None,
    ) -> None:
        self.spec.files.append(path)
        try:
            root = ET.parse(path).getroot()
        except ET.ParseError as err:
            raise LaunchError(f"{path}: malformed XML: {err}") from err
        except OSError as err:
            raise LaunchError(f"{path}: cannot read: {err.strerror}") from err
        if root.tag != "launch":
            raise LaunchError(f"{path}: the root element must be <launch>, not <{root.tag}>")
        scope = _Scope(path, dict(args), ns, dict(remaps or {}), env)
        self.children(root, scope, passed=set(args))

    def children(self, parent: ET.Element, scope: _Scope, passed: set[str]) -> None:
        for elem in parent:
            if not isinstance(elem.tag, str) or not self.enabled(elem, scope):
                continue
            handler = self._handlers().get(elem.tag)
            if handler is None:
                raise LaunchError(f"{_where(scope, elem)}: unknown launch element")
            handler(elem, scope, passed)

    def _handlers(self) -> dict[str, Callable[[ET.Element, _Scope, set[str]], None]]:
        return {
            "arg": self.on_arg,
            "param": lambda e, s, p: self.on_param(e, s, self.spec.params, s.ns),
            "rosparam": lambda e, s, p: self.on_rosparam(e, s, self.spec.params, s.ns),
            "node": self.on_node,
            "include": self.on_include,
            "group": self.on_group,
            "remap": self.on_remap,
            "env": self.on_env,
            "machine": lambda e, s, p: None,
            "test": lambda e, s, p: None,
            "master": lambda e, s, p: None,
        }

    def on_arg(self, elem: ET.Element, scope: _Scope, passed: set[str]) -> None:
        name = self.attr(elem, "name", scope)
        if "value" in elem.attrib and "default" in elem.attrib:
            raise LaunchError(f"{_where(scope, elem)}: arg '{name}' has both value and default")
        if "value" in elem.attrib:
            if name in passed:
                raise LaunchError(
                    f"{_where(scope, elem)}: arg '{name}' has a fixed value and cannot be set"
                )
            scope.args[name] = self.attr(elem, "value", scope)
        elif name not in scope.args and "default" in elem.attrib:
            scope.args[name] = self.attr(elem, "default", scope)

    def on_param(self, elem: ET.Element, scope: _Scope, into: dict[str, Any], ns: str) -> None:
        name = self.attr(elem, "name", scope)
        if "value" in elem.attrib:
            value: Any = _typed(self.attr(elem, "value", scope), elem.get("type"))
        elif "command" in elem.attrib:
            value = self._command(self.attr(elem, "command", scope), scope, elem)
        elif "textfile" in elem.attrib:
            value = self._read_text(Path(self.attr(elem, "textfile", scope)), scope, elem)
        elif "binfile" in elem.attrib:
            value = Path(self.attr(elem, "binfile", scope)).read_bytes()
        else:
            raise LaunchError(f"{_where(scope, elem)}: param '{name}' has no value")
        into[_join(ns, name)] = value

    def on_rosparam(self, elem: ET.Element, scope: _Scope, into: dict[str, Any], ns: str) -> None:
        command = self.attr(elem, "command", scope, "load")
        sub_ns = _join(ns, self.attr(elem, "ns", scope, "")) if elem.get("ns") else ns
        if command == "delete":
            return
        if command == "dump":
            return
        if command != "load":
            raise LaunchError(f"{_where(scope, elem)}: rosparam command {command!r} unknown")
        if "file" in elem.attrib:
            text = self._read_text(Path(self.attr(elem, "file", scope)), scope, elem)
        else:
            text = self.subst(elem.text or "", scope, elem)
        try:
            data = yaml.safe_load(text) if text.strip() else None
        except yaml.YAMLError as err:
            raise LaunchError(f"{_where(scope, elem)}: malformed YAML: {err}") from err
        if data is None:
            return
        param = elem.get("param")
        if param:
            into[_join(sub_ns, self.subst(param, scope, elem))] = data
            return
        if not isinstance(data, dict):
            raise LaunchError(f"{_where(scope, elem)}: rosparam YAML must be a mapping")
        for key, value in _flatten(data).items():
            into[_join(sub_ns, key)] = value

    def on_node(self, elem: ET.Element, scope: _Scope, passed: set[str]) -> None:
        pkg = self.attr(elem, "pkg", scope)
        typ = self.attr(elem, "type", scope)
        name = self.attr(elem, "name", scope, typ.removesuffix(".py"))
        ns = _join(scope.ns, self.attr(elem, "ns", scope, "")) if elem.get("ns") else scope.ns
        node = NodeSpec(
            pkg=pkg,
            type=typ,
            name=name,
            namespace=ns or "/",
            args=self.attr(elem, "args", scope, ""),
            remaps=dict(scope.remaps),
            source=_where(scope, elem),
            env=dict(scope.env),
        )
        self.on_process_attrs(elem, scope, node)
        for child in elem:
            if not isinstance(child.tag, str) or not self.enabled(child, scope):
                continue
            if child.tag == "param":
                self.on_param(child, scope, node.params, "")
            elif child.tag == "rosparam":
                self.on_rosparam(child, scope, node.params, "")
            elif child.tag == "remap":
                node.remaps[self.attr(child, "from", scope)] = self.attr(child, "to", scope)
            elif child.tag == "env":
                self.env_into(child, scope, node.env)
            else:
                raise LaunchError(f"{_where(scope, child)}: not allowed inside <node>")
        node.params = {k.lstrip("/"): v for k, v in node.params.items()}
        # clear_params="true": roslaunch empties the node's private namespace on the
        # parameter server before it sets this launch's parameters. roverlab keeps no
        # parameters between launches, so a node's private parameters are always this
        # launch's only: the attribute is checked and holds already.
        clear = self.attr(elem, "clear_params", scope, "false").lower()
        if clear not in ("true", "false", "1", "0"):
            raise LaunchError(f"{_where(scope, elem)}: clear_params must be true or false")
        node.clear_params = clear in ("true", "1")
        self.spec.nodes.append(node)

    def on_process_attrs(self, elem: ET.Element, scope: _Scope, node: NodeSpec) -> None:
        """roslaunch's process attributes: output, respawn, respawn_delay, required."""
        where = _where(scope, elem)
        node.output = self.attr(elem, "output", scope, "log")
        if node.output not in ("log", "screen"):
            raise LaunchError(f"{where}: output must be 'log' or 'screen', not {node.output!r}")
        flags = {}
        for name in ("respawn", "required"):
            text = self.attr(elem, name, scope, "false").strip().lower()
            if text not in ("true", "false"):
                raise LaunchError(f"{where}: {name} must be true or false, not {text!r}")
            flags[name] = text == "true"
        node.respawn, node.required = flags["respawn"], flags["required"]
        if node.respawn and node.required:
            raise LaunchError(f"{where}: respawn and required cannot both be true")
        delay = self.attr(elem, "respawn_delay", scope, "0")
        try:
            node.respawn_delay = float(delay)
        except ValueError:
            raise LaunchError(f"{where}: respawn_delay must be a number, not {delay!r}") from None
        if not (node.respawn_delay >= 0.0 and node.respawn_delay < float("inf")):
            raise LaunchError(f"{where}: respawn_delay must be >= 0 seconds, not {delay}")

    def on_include(self, elem: ET.Element, scope: _Scope, passed: set[str]) -> None:
        path = Path(self.attr(elem, "file", scope))
        if not path.is_absolute():
            path = scope.path.parent / path
        ns = _join(scope.ns, self.attr(elem, "ns", scope, "")) if elem.get("ns") else scope.ns
        args: dict[str, str] = {}
        env = dict(scope.env)
        for child in elem:
            if not isinstance(child.tag, str) or not self.enabled(child, scope):
                continue
            if child.tag == "arg":
                name = self.attr(child, "name", scope)
                if "value" in child.attrib:
                    args[name] = self.attr(child, "value", scope)
                elif "default" in child.attrib:
                    args[name] = self.attr(child, "default", scope)
            elif child.tag == "env":
                self.env_into(child, scope, env)
            else:
                raise LaunchError(f"{_where(scope, child)}: not allowed inside <include>")
        if elem.get("pass_all_args", "false").lower() == "true":
            args = {**scope.args, **args}
        if not path.is_file():
            raise LaunchError(f"{_where(scope, elem)}: included file {path} does not exist")
        self.read_file(path, args, ns or "/", scope.remaps, env)

    def on_group(self, elem: ET.Element, scope: _Scope, passed: set[str]) -> None:
        ns = _join(scope.ns, self.attr(elem, "ns", scope, "")) if elem.get("ns") else scope.ns
        inner = _Scope(scope.path, scope.args, ns or "/", dict(scope.remaps), scope.env)
        inner.anon = scope.anon
        self.children(elem, inner, passed)

    def on_remap(self, elem: ET.Element, scope: _Scope, passed: set[str]) -> None:
        scope.remaps[self.attr(elem, "from", scope)] = self.attr(elem, "to", scope)

    def on_env(self, elem: ET.Element, scope: _Scope, passed: set[str]) -> None:
        self.env_into(elem, scope, scope.env)

    def env_into(self, elem: ET.Element, scope: _Scope, env: dict[str, str]) -> None:
        """``<env>``: set for the nodes of its scope (roslaunch gives it to their
        processes; roverlab sets it while such a node is created), not for the launch."""
        env[self.attr(elem, "name", scope)] = self.attr(elem, "value", scope)

    # ------------------------------------------------------------- helpers
    def _read_text(self, path: Path, scope: _Scope, elem: ET.Element) -> str:
        try:
            return path.read_text(encoding="utf-8")
        except OSError as err:
            raise LaunchError(f"{_where(scope, elem)}: cannot read {path}: {err.strerror}") from err

    def _command(self, command: str, scope: _Scope, elem: ET.Element) -> str:
        """``command=``: xacro runs in-process (roverlab's hooked xacro); others in a shell."""
        try:
            argv = shlex.split(command)
        except ValueError as err:
            raise LaunchError(f"{_where(scope, elem)}: cannot parse command: {err}") from err
        xacro_argv = _xacro_argv(argv)
        if xacro_argv is not None:
            return self._xacro(xacro_argv, scope, elem)
        try:
            done = subprocess.run(command, shell=True, capture_output=True, text=True, check=False)
        except OSError as err:
            raise LaunchError(f"{_where(scope, elem)}: command failed: {err}") from err
        if done.returncode != 0:
            first = (done.stderr.strip().splitlines() or ["no output"])[0]
            raise LaunchError(f"{_where(scope, elem)}: command exited {done.returncode}: {first}")
        return done.stdout

    def _xacro(self, argv: list[str], scope: _Scope, elem: ET.Element) -> str:
        """ROS 1's xacro command line: ``--inorder`` / ``-i`` (the default since melodic,
        accepted and ignored), ``--xacro-ns``, ``-o FILE`` (the output is the parameter
        anyway), ``name:=value`` mappings and one input file."""
        files: list[str] = []
        mappings: dict[str, str] = {}
        xacro_ns = False
        skip = False
        for a in argv:
            if skip:
                skip = False
            elif a in ("--inorder", "-i", "--legacy", "--check-order"):
                continue
            elif a == "--xacro-ns":
                xacro_ns = True
            elif a in ("-o", "--output"):
                skip = True
            elif ":=" in a:
                name, value = a.split(":=", 1)
                mappings[name] = value
            elif a.startswith("-"):
                raise LaunchError(f"{_where(scope, elem)}: xacro option {a!r} is not supported")
            else:
                files.append(a)
        if len(files) != 1:
            raise LaunchError(f"{_where(scope, elem)}: xacro command needs one input file")
        try:
            return robot_description(
                Path(files[0]), mappings, package_path=self.package_path, xacro_ns=xacro_ns
            )
        except DescriptionError as err:
            raise LaunchError(f"{_where(scope, elem)}: {err}") from err


def _xacro_argv(argv: list[str]) -> list[str] | None:
    """The xacro arguments of a ``command=`` running xacro in any of ROS 1's spellings
    (``xacro``, ``xacro.py``, ``$(find xacro)/xacro[.py]``, ``python[3] .../xacro.py``,
    ``rosrun xacro xacro[.py]``), else ``None``."""
    rest = list(argv)
    if rest and Path(rest[0]).name in ("python", "python2", "python3"):
        rest = rest[1:]
    if len(rest) >= 3 and rest[0] == "rosrun" and rest[1] == "xacro":
        rest = rest[2:]
    if rest and Path(rest[0]).name in ("xacro", "xacro.py"):
        return rest[1:]
    return None


def _join(ns: str, name: str) -> str:
    if name.startswith("/"):
        return name
    base = ns.rstrip("/")
    return f"{base}/{name}" if name else (base or "/")


def _flatten(data: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in data.items():
        name = f"{prefix}{key}"
        if isinstance(value, Mapping):
            out.update(_flatten(value, name + "/"))
        else:
            out[name] = value
    return out


def _typed(text: str, declared: str | None = None) -> Any:
    """A ``<param value>`` as roslaunch types it (or as ``type=`` says)."""
    if declared == "str" or declared == "string":
        return text
    if declared == "yaml":
        return yaml.safe_load(text)
    t = text.strip()
    if declared in ("int", "double", "bool"):
        try:
            if declared == "int":
                return int(t)
            if declared == "double":
                return float(t)
            return t.lower() in _TRUE
        except ValueError as err:
            raise LaunchError(f"param value {text!r} is not a valid {declared}") from err
    if t.lower() in ("true", "false"):
        return t.lower() == "true"
    for conv in (int, float):
        try:
            return conv(t)
        except ValueError:
            pass
    return text


def load_launch(
    path: str | Path, args: Mapping[str, str] | None = None, *, package_path: tuple[str, ...] = ()
) -> LaunchSpec:
    """Read a launch file (and its includes) with command-line ``args``.

    Raises:
        LaunchError: one line naming the file and element at fault.
    """
    reader = _Reader(package_path)
    p = Path(path)
    if not p.is_file():
        raise LaunchError(f"{p}: no such launch file")
    reader.read_file(p, dict(args or {}))
    return reader.spec
