"""roslaunch XML: ``<launch>`` files read into a flat description of nodes and parameters.

Supported as roslaunch does: ``<arg>`` (default/value, command-line ``name:=value``),
``<param>`` (value/type, ``command=``, ``textfile=``, ``binfile=``), ``<rosparam>``
(``command="load" file=``, inline YAML, ``ns``/``param``), ``<node>`` (pkg, type, name, args,
ns, output, respawn, required, and its ``<param>``/``<rosparam>``/``<remap>`` children),
``<include file=...>`` with ``<arg>`` children and ``ns``, ``<group ns=...>``, top-level
``<remap>``, ``<env>``, ``if=``/``unless=`` on every element, and the substitutions
``$(find pkg)``, ``$(arg name)``, ``$(env VAR)``, ``$(optenv VAR default)``,
``$(anon name)``, ``$(dirname)`` and ``$(eval expr)``. ``<machine>``, ``<test>`` and
``<master>`` are read (roverlab runs every node here and needs no master; a ``<test>``
and a remote machine are reported), and so is an attribute roslaunch does not know, in
:attr:`LaunchSpec.warnings`. Every error names the file and the element.
"""

from __future__ import annotations

import math
import os
import re
import socket
import xml.etree.ElementTree as ET
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import yaml

from roverlab.description import find_package
from roverlab.description.errors import DescriptionError
from roverlab.launch.commands import command_value, xacro_argv, xacro_input
from roverlab.launch.errors import LaunchError
from roverlab.launch.spec import LaunchSpec, NodeSpec

__all__ = ["LaunchError", "LaunchSpec", "NodeSpec", "load_launch"]


_SUBST = re.compile(r"\$\((\w+)((?:\s+[^()]*)?)\)")
_TRUE = {"true", "1"}
_FALSE = {"false", "0"}
# roslaunch's $(eval) builtins (the math module's names are there too)
_EVAL_BUILTINS = {"list": list, "dict": dict, "map": map, "str": str, "float": float, "int": int}
# the attributes roslaunch knows on each element (if/unless on every one)
_ATTRS = {
    "launch": {"deprecated"},
    "arg": {"name", "value", "default", "doc"},
    "param": {"name", "value", "type", "textfile", "binfile", "command"},
    "rosparam": {"command", "ns", "file", "param", "subst_value"},
    "node": {"pkg", "type", "machine", "name", "args", "output", "respawn", "respawn_delay",
             "cwd", "ns", "clear_params", "launch-prefix", "required"},
    "include": {"file", "ns", "clear_params", "pass_all_args"},
    "group": {"ns", "clear_params"},
    "remap": {"from", "to"},
    "env": {"name", "value"},
    "machine": {"name", "address", "env-loader", "ssh-port", "user", "password", "default",
                "timeout"},
    "test": {"pkg", "type", "machine", "name", "args", "cwd", "ns", "clear_params",
             "launch-prefix", "required", "test-name", "time-limit", "retry"},
    "master": {"auto"},
}  # fmt: skip
_LOCAL_HOSTS = {"localhost", "127.0.0.1", "::1"}


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
        self.private: dict[str, Any] = {}  # <param name="~x">: for the nodes declared after it
        self.declared: set[str] = set()  # the <arg> names this file declared


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
        if "__" in expr:
            raise LaunchError(
                f"{_where(scope, elem)}: $(eval) may not contain double underscore expressions"
            )
        env: dict[str, Any] = {
            **{k: v for k, v in vars(math).items() if not k.startswith("_")},
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
            value = eval(expr, {"__builtins__": _EVAL_BUILTINS, "math": math}, env)
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
        if "if" in elem.attrib and "unless" in elem.attrib:
            raise LaunchError(f"{_where(scope, elem)}: cannot set both 'if' and 'unless'")
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
        private: dict[str, Any] | None = None,
    ) -> _Scope:
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
        scope.private = dict(private or {})
        self.check_attrs(root, scope)
        if root.get("deprecated"):
            self.warn(scope, root, f"deprecated: {self.attr(root, 'deprecated', scope)}")
        self.children(root, scope, passed=set(args))
        return scope

    def warn(self, scope: _Scope, elem: ET.Element, message: str) -> None:
        self.spec.warnings.append(f"{_where(scope, elem)}: {message}")

    def check_attrs(self, elem: ET.Element, scope: _Scope) -> None:
        """roslaunch's warning for an attribute it does not know (a typo, mostly)."""
        for name in sorted(set(elem.attrib) - _ATTRS.get(str(elem.tag), set()) - {"if", "unless"}):
            self.warn(scope, elem, f"unknown attribute '{name}' (roslaunch ignores it too)")

    def flag(self, elem: ET.Element, name: str, scope: _Scope) -> bool:
        """A true/false attribute (false when absent)."""
        text = self.attr(elem, name, scope, "false").strip().lower()
        if text not in ("true", "false"):
            raise LaunchError(f"{_where(scope, elem)}: {name} must be true or false, not {text!r}")
        return text == "true"

    def child_ns(self, elem: ET.Element, scope: _Scope) -> str:
        """The namespace an element's ``ns=`` (and ``clear_params=``) makes."""
        if "ns" not in elem.attrib:
            if self.flag(elem, "clear_params", scope) and elem.tag != "node":
                raise LaunchError(f"{_where(scope, elem)}: clear_params needs an ns attribute")
            return scope.ns
        ns = self.attr(elem, "ns", scope)
        if not ns:
            raise LaunchError(f"{_where(scope, elem)}: empty ns attribute")
        # clear_params: roslaunch empties the namespace before this launch sets its
        # parameters; roverlab keeps none between launches, so it holds already
        self.flag(elem, "clear_params", scope)
        return _join(scope.ns, ns) or "/"

    def children(self, parent: ET.Element, scope: _Scope, passed: set[str]) -> None:
        for elem in parent:
            if not isinstance(elem.tag, str) or not self.enabled(elem, scope):
                continue
            handler = self._handlers().get(elem.tag)
            if handler is None:
                raise LaunchError(f"{_where(scope, elem)}: unknown launch element")
            self.check_attrs(elem, scope)
            handler(elem, scope, passed)

    def _handlers(self) -> dict[str, Callable[[ET.Element, _Scope, set[str]], None]]:
        return {
            "arg": self.on_arg,
            "param": lambda e, s, p: self.on_param(e, s, None),
            "rosparam": lambda e, s, p: self.on_rosparam(e, s, None),
            "node": self.on_node,
            "include": self.on_include,
            "group": self.on_group,
            "remap": self.on_remap,
            "env": self.on_env,
            "machine": self.on_machine,
            "test": lambda e, s, p: self.warn(
                s, e, f"test '{e.get('test-name', '')}' not run: roslaunch leaves tests to rostest"
            ),
            # <master auto="start">: roslaunch starts a master when none runs; roverlab's
            # nodes need none (they meet through the daemon), so it holds already
            "master": lambda e, s, p: None,
        }

    def on_arg(self, elem: ET.Element, scope: _Scope, passed: set[str]) -> None:
        name = self.attr(elem, "name", scope)
        if name in scope.declared:
            raise LaunchError(f"{_where(scope, elem)}: arg '{name}' has already been declared")
        scope.declared.add(name)
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

    def put(self, scope: _Scope, name: str, value: Any, node: NodeSpec | None, source: str) -> None:
        """Set a parameter as roslaunch does: ``~name`` is private (to the ``node``, or to
        every node declared after it in this scope), ``/name`` global, else in the scope's
        namespace (a node's private one inside ``<node>``). ``source``: where the value
        came from (:attr:`LaunchSpec.param_sources` of a global one)."""
        if name.startswith("/"):
            full = name.rstrip("/")
        elif node is not None:
            node.params[name.lstrip("~").strip("/")] = value
            return
        elif name.startswith("~"):
            scope.private[name[1:].strip("/")] = value
            return
        else:
            full = _join(scope.ns, name.rstrip("/"))
        self.spec.params[full] = value
        self.spec.param_sources[full] = source

    def on_param(self, elem: ET.Element, scope: _Scope, node: NodeSpec | None) -> None:
        name = self.attr(elem, "name", scope).strip()
        sources = [k for k in ("value", "textfile", "binfile", "command") if k in elem.attrib]
        if len(sources) != 1:
            raise LaunchError(
                f"{_where(scope, elem)}: param '{name}' needs one and only one of "
                "value/textfile/binfile/command"
            )
        where = _where(scope, elem)
        text = self.attr(elem, sources[0], scope)
        source = where  # the file it read, when there is one
        value: Any
        if sources[0] == "value":
            try:
                value = _typed(text, elem.get("type"))
            except LaunchError as err:
                raise LaunchError(f"{where}: {err}") from err
        elif sources[0] == "command":
            value = command_value(text, where, self.package_path)
            source = xacro_input(text) or where
        elif sources[0] == "textfile":
            value = self._read_text(Path(text), scope, elem)
            source = text
        else:
            try:
                value = Path(text).read_bytes()
            except OSError as err:
                raise LaunchError(f"{where}: cannot read {text}: {err.strerror}") from err
        self.put(scope, name, value, node, source)

    def on_rosparam(self, elem: ET.Element, scope: _Scope, node: NodeSpec | None) -> None:
        where = _where(scope, elem)
        command = self.attr(elem, "command", scope, "load")
        param = _rel(self.attr(elem, "ns", scope, ""), self.attr(elem, "param", scope, ""))
        if command not in ("load", "dump", "delete"):
            raise LaunchError(f"{where}: rosparam command {command!r} unknown (load/dump/delete)")
        if command == "delete":
            # roslaunch deletes before it sets this launch's parameters; roverlab keeps
            # none between launches, so what it deletes is never there
            if "file" in elem.attrib:
                raise LaunchError(f"{where}: rosparam delete takes no file")
            return
        if command == "dump":
            self.warn(
                scope,
                elem,
                "rosparam dump not done: roslaunch dumps the parameter server before this "
                "launch sets its parameters, and roverlab keeps none between launches "
                "(`roverlab param dump` reads a running node's)",
            )
            return
        if "file" in elem.attrib:
            text = self._read_text(Path(self.attr(elem, "file", scope)), scope, elem)
        else:
            text = "".join(elem.itertext())
        if self.flag(elem, "subst_value", scope):
            text = self.subst(text, scope, elem)
        try:
            data = yaml.safe_load(text) if text.strip() else None
        except yaml.YAMLError as err:
            raise LaunchError(f"{where}: malformed YAML: {' '.join(str(err).split())}") from err
        if data is None:
            return
        if not isinstance(data, dict):
            if not param:
                raise LaunchError(f"{where}: a rosparam value that is not a mapping needs param=")
            self.put(scope, param, data, node, where)
            return
        if not param and node is None and scope.ns == "/" and not data:
            return
        for key, value in _flatten(data).items():
            self.put(scope, _rel(param, key), value, node, where)

    def on_node(self, elem: ET.Element, scope: _Scope, passed: set[str]) -> None:
        pkg = self.attr(elem, "pkg", scope)
        typ = self.attr(elem, "type", scope)
        name = self.attr(elem, "name", scope)
        if not name or "/" in name or "~" in name:
            raise LaunchError(f"{_where(scope, elem)}: illegal node name {name!r}")
        ns = self.child_ns(elem, scope)
        node = NodeSpec(
            pkg=pkg,
            type=typ,
            name=name,
            namespace=ns or "/",
            args=self.attr(elem, "args", scope, ""),
            params=dict(scope.private),
            remaps=dict(scope.remaps),
            source=_where(scope, elem),
            env=dict(scope.env),
        )
        self.on_process_attrs(elem, scope, node)
        for child in elem:
            if not isinstance(child.tag, str) or not self.enabled(child, scope):
                continue
            if child.tag not in ("param", "rosparam", "remap", "env"):
                raise LaunchError(f"{_where(scope, child)}: not allowed inside <node>")
            self.check_attrs(child, scope)
            if child.tag == "param":
                self.on_param(child, scope, node)
            elif child.tag == "rosparam":
                self.on_rosparam(child, scope, node)
            elif child.tag == "remap":
                node.remaps[self.attr(child, "from", scope)] = self.attr(child, "to", scope)
            else:
                self.env_into(child, scope, node.env)
        # clear_params="true": roslaunch empties the node's private namespace on the
        # parameter server before it sets this launch's parameters. roverlab keeps no
        # parameters between launches, so a node's private parameters are always this
        # launch's only: the attribute is checked and holds already.
        node.clear_params = self.flag(elem, "clear_params", scope)
        if elem.get("machine"):
            self.warn(
                scope,
                elem,
                f"machine={self.attr(elem, 'machine', scope)!r}: the node runs on this machine",
            )
        self.spec.nodes.append(node)

    def on_process_attrs(self, elem: ET.Element, scope: _Scope, node: NodeSpec) -> None:
        """roslaunch's process attributes: output, respawn, respawn_delay, required, cwd,
        launch-prefix."""
        where = _where(scope, elem)
        node.output = self.attr(elem, "output", scope, "log")
        if node.output not in ("log", "screen"):
            raise LaunchError(f"{where}: output must be 'log' or 'screen', not {node.output!r}")
        node.respawn, node.required = (self.flag(elem, k, scope) for k in ("respawn", "required"))
        if node.respawn and node.required:
            raise LaunchError(f"{where}: respawn and required cannot both be true")
        delay = self.attr(elem, "respawn_delay", scope, "0")
        try:
            node.respawn_delay = float(delay)
        except ValueError:
            raise LaunchError(f"{where}: respawn_delay must be a number, not {delay!r}") from None
        if not (node.respawn_delay >= 0.0 and node.respawn_delay < float("inf")):
            raise LaunchError(f"{where}: respawn_delay must be >= 0 seconds, not {delay}")
        node.cwd = self.attr(elem, "cwd", scope) if "cwd" in elem.attrib else None
        if node.cwd not in (None, "ROS_HOME", "node"):
            raise LaunchError(f"{where}: cwd must be 'ROS_HOME' or 'node', not {node.cwd!r}")
        node.launch_prefix = self.attr(elem, "launch-prefix", scope, "")

    def on_include(self, elem: ET.Element, scope: _Scope, passed: set[str]) -> None:
        path = Path(self.attr(elem, "file", scope))
        if not path.is_absolute():
            path = scope.path.parent / path
        ns = self.child_ns(elem, scope)
        args: dict[str, str] = {}
        env = dict(scope.env)
        for child in elem:
            if not isinstance(child.tag, str) or not self.enabled(child, scope):
                continue
            self.check_attrs(child, scope)
            if child.tag == "arg":
                name = self.attr(child, "name", scope)
                if "value" in child.attrib:
                    args[name] = self.attr(child, "value", scope)
                elif "default" in child.attrib:
                    args[name] = self.attr(child, "default", scope)
                else:
                    raise LaunchError(f"{_where(scope, child)}: include args need a value")
            elif child.tag == "env":
                self.env_into(child, scope, env)
            else:
                raise LaunchError(f"{_where(scope, child)}: not allowed inside <include>")
        pass_all = self.flag(elem, "pass_all_args", scope)
        if pass_all:
            args = {**scope.args, **args}
        if not path.is_file():
            raise LaunchError(f"{_where(scope, elem)}: included file {path} does not exist")
        inner = self.read_file(path, args, ns or "/", scope.remaps, env, scope.private)
        unused = sorted(set(args) - inner.declared)
        if unused and not pass_all:
            raise LaunchError(
                f"{_where(scope, elem)}: unused args [{', '.join(unused)}] for include of {path}"
            )

    def on_group(self, elem: ET.Element, scope: _Scope, passed: set[str]) -> None:
        ns = self.child_ns(elem, scope)
        inner = _Scope(scope.path, scope.args, ns or "/", dict(scope.remaps), scope.env)
        inner.anon = scope.anon
        inner.declared = scope.declared  # the same file: one set of <arg> names
        inner.private = dict(scope.private)
        self.children(elem, inner, passed)

    def on_machine(self, elem: ET.Element, scope: _Scope, passed: set[str]) -> None:
        """``<machine>``: nodes on another computer (over ssh) in roslaunch; roverlab runs
        every node on this one, and says so for a machine that is not this one."""
        name = self.attr(elem, "name", scope)
        address = self.attr(elem, "address", scope)
        if address not in _LOCAL_HOSTS and address != socket.gethostname():
            self.warn(
                scope,
                elem,
                f"machine '{name}' ({address}): roverlab starts every node on this machine",
            )

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


def _join(ns: str, name: str) -> str:
    if name.startswith("/"):
        return name
    base = ns.rstrip("/")
    return f"{base}/{name}" if name else (base or "/")


def _rel(prefix: str, name: str) -> str:
    """``name`` in ``prefix`` (both relative; an absolute ``name`` stays as it is)."""
    if name.startswith("/") or not prefix:
        return name
    return f"{prefix.rstrip('/')}/{name}" if name else prefix


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
    kind = (declared or "auto").strip().lower()
    t = text.strip()
    if kind in ("str", "string"):
        return text
    if kind == "yaml":
        try:
            return yaml.safe_load(text)
        except yaml.YAMLError as err:
            problem = " ".join(str(err).split())
            raise LaunchError(f"param value is not valid YAML: {problem}") from err
    if kind in ("bool", "boolean"):
        if t.lower() not in _TRUE | _FALSE:
            raise LaunchError(f"param value {text!r} is not a valid bool (true/false/1/0)")
        return t.lower() in _TRUE
    if kind in ("int", "double"):
        try:
            return int(t) if kind == "int" else float(t)
        except ValueError as err:
            raise LaunchError(f"param value {text!r} is not a valid {kind}") from err
    if kind != "auto":
        raise LaunchError(f"unknown param type {declared!r} (str, int, double, bool, yaml)")
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
    top = reader.read_file(p, dict(args or {}))
    for name in sorted(set(args or {}) - top.declared):  # roslaunch takes them silently
        reader.spec.warnings.append(
            f'{p}: {name}:= on the command line, but the file declares no <arg name="{name}">'
        )
    return reader.spec


_xacro_argv = xacro_argv  # the name the tests know
