"""The dashboard's node: subscribes to what the displays draw, publishes what the tools make.

:class:`VizBridge` is the only part of :mod:`roverlab.viz` that touches the bus. It holds
the :class:`~roverlab.viz.config.DashboardConfig` and one :class:`DisplayState` per display
(its subscription, its newest frame, its status). Subscription callbacks run on the
executor thread and only store the newest data with a version number; the web server's
threads read snapshots and compare versions, so each client gets only what changed. What a
message becomes is each display type's own handler (:mod:`roverlab.viz.handlers`, one per
display, as rviz has one plugin per display). Configuration changes from the page are
applied on the executor thread (:meth:`VizBridge.set_config`).

The status tree the page shows (:meth:`VizBridge.status`) is built by
:class:`~roverlab.viz.status.DisplayStatus`, a base class of :class:`VizBridge`.
"""

from __future__ import annotations

import dataclasses
import io
import math
import re
import threading
import time
from collections.abc import Callable, Sequence
from functools import partial
from pathlib import Path
from typing import Any, Final

import numpy as np
from PIL import Image

from roverlab.core import Context, Node, QoSProfile, Time
from roverlab.description.urdf import parse_urdf
from roverlab.errors import RoverlabError
from roverlab.geometry import Transform3, yaw_from_quat
from roverlab.maps import save_map
from roverlab.msgs import (
    JointState,
    PointStamped,
    PoseStamped,
    PoseWithCovarianceStamped,
    String,
    image_to_array,
    occupancy_grid_to_array,
    pose_from_xytheta,
    stamp_to_msg,
    yaw_from_quaternion,
)
from roverlab.teleop import SPEED_BINDINGS, twist_for_key
from roverlab.teleop.node import command_to_twist
from roverlab.tf import Buffer, TransformException, TransformListener
from roverlab.viz.config import (
    DISPLAY_KINDS,
    DashboardConfig,
    DisplayConfig,
    default_config,
)
from roverlab.viz.displays import (
    MarkerStore,
    PoseTrail,
)
from roverlab.viz.errors import DashboardError
from roverlab.viz.handlers import HANDLERS, DisplayState, Versioned, markers_changed
from roverlab.viz.joints import SLIDER_TOPIC, JointSliders
from roverlab.viz.protocol import (
    INITIALPOSE_COVARIANCE,
    VisualOutline,
    colorize,
    encode_image,
    encode_image_file,
    image_to_rgb8,
    robot_outlines,
    robot_shapes,
)
from roverlab.viz.status import DisplayStatus, RateMeter, TopicInfo

__all__ = [
    "COMPRESSED_TYPE",
    "IMAGE_TYPE",
    "DisplayState",
    "RvizNode",
    "TopicInfo",
    "Versioned",
    "VizBridge",
]

IMAGE_TYPE: Final = "sensor_msgs/msg/Image"
COMPRESSED_TYPE: Final = "sensor_msgs/msg/CompressedImage"
_LATCHED: Final = QoSProfile(depth=1, durability="transient_local")
_MAX_PATCHES: Final = 16
_RATE_WINDOW_S: Final = 3.0
#: /clock going back by more than this is a restarted bag or simulation (rviz resets then)
_JUMP_BACK_NS: Final = 1_000_000_000
_MAP_NAME: Final = re.compile(r"^[A-Za-z0-9_.-]{1,100}$")


class RvizNode(Node):
    """The dashboard's node; :attr:`on_destroy` callbacks run when it is destroyed (the
    context shutting down stops the web server with it). :attr:`server` is the
    :class:`~roverlab.viz.server.DashboardServer` serving it, if any."""

    def __init__(self, node_name: str, *, context: Context) -> None:
        super().__init__(node_name, context=context)
        self.on_destroy: list[Callable[[], None]] = []
        self.server: Any = None

    def destroy_node(self) -> None:
        callbacks, self.on_destroy = self.on_destroy, []
        for callback in callbacks:
            callback()
        super().destroy_node()


def _xyyaw(t: Transform3) -> list[float]:
    return [
        round(t.translation[0], 4),
        round(t.translation[1], 4),
        round(yaw_from_quat(t.rotation), 4),
    ]


class VizBridge(DisplayStatus):
    """Subscriptions and publishers of the dashboard in ``context``.

    Args:
        context: the context to attach to (in-process, or a :class:`Connection`'s).
        fixed_frame: frame the displays are drawn in when ``config`` is not given.
        config: the displays; :func:`~roverlab.viz.config.default_config` when None.
        speed_mps: linear speed of the drive keys (teleop_twist_keyboard's ``~speed``).
        turn_radps: angular speed of the drive keys (``~turn``).
        map_dir: where the Save map button writes (map_saver's working directory).
        remote_graph: returns the other processes' publishers and subscriptions
            (:meth:`Connection.graph`); None in-process.
        remote_counts: returns the messages the other processes published per topic
            (:meth:`Connection.topic_counts`), for the topics' rates; None in-process.
        node_name: name of the node.
    """

    def __init__(
        self,
        *,
        context: Context,
        fixed_frame: str = "map",
        config: DashboardConfig | None = None,
        speed_mps: float = 0.3,
        turn_radps: float = 0.5,
        map_dir: str | Path = ".",
        remote_graph: Callable[[], Sequence[Any]] | None = None,
        remote_counts: Callable[[], dict[str, dict[str, int]]] | None = None,
        node_name: str = "rviz",
    ) -> None:
        self.context = context
        self.speed_mps = speed_mps
        self.turn_radps = turn_radps
        self.map_dir = Path(map_dir)
        self.node = RvizNode(node_name, context=context)
        self.tf_buffer = Buffer()
        self._listener = TransformListener(self.tf_buffer, self.node)
        self._lock = threading.Lock()
        self._version = 0
        self._remote_graph = remote_graph
        self._remote: list[Any] = []
        self._remote_counts = remote_counts
        self._rates = RateMeter(_RATE_WINDOW_S)  # counted by the publishing processes
        self._subscribed_rates = RateMeter(_RATE_WINDOW_S)  # counted by the displays
        self.outlines: Versioned | None = None
        self.shapes: list[dict[str, Any]] = []
        self.joint_sliders: JointSliders | None = None
        self._slider_pub: Any = None
        self._description_sub: Any = None
        self._description_topic = ""
        self._description_text = ""  # the robot description shown now
        self.config = config if config is not None else default_config(fixed_frame)
        self.config_version = 1
        self.displays: list[DisplayState] = []
        node = self.node
        self.goal_pub = node.create_publisher(
            "geometry_msgs/msg/PoseStamped", "/move_base_simple/goal", 1
        )
        self.initialpose_pub = node.create_publisher(
            "geometry_msgs/msg/PoseWithCovarianceStamped", "/initialpose", 1
        )
        self.point_pub = node.create_publisher(
            "geometry_msgs/msg/PointStamped", "/clicked_point", 1
        )
        self.cmd_vel_pub = node.create_publisher("geometry_msgs/msg/Twist", "/cmd_vel", 1)
        node.create_timer(0.1, self._refresh_markers)  # lifetimes and frame-locked markers
        self._clock_ns: int | None = None
        if not context.uses_sim_time:
            # on the wall clock (`roverlab dashboard`), watch /clock for a bag played again;
            # on a simulation's clock the TF listener sees jumps itself, and /clock keeps
            # pausing while nobody else reads it
            node.create_subscription("rosgraph_msgs/msg/Clock", "/clock", self._on_clock, 1)
        self._apply(self.config)

    # ------------------------------------------------------------------ state
    def next_version(self) -> int:
        with self._lock:
            self._version += 1
            return self._version

    @property
    def requested_fixed_frame(self) -> str:
        """The configuration's fixed frame."""
        return self.config.fixed_frame

    @property
    def fixed_frame(self) -> str:
        """The requested fixed frame if TF knows it, else ``odom`` (a warning in the status)."""
        want = self.config.fixed_frame
        if self.tf_buffer.has_frame(want) or not self.tf_buffer.has_frame("odom"):
            return want
        return "odom"

    def _lookup(self, frame: str, stamp: Time | None = None) -> Transform3 | None:
        tf, _ = self.lookup_why(frame, stamp)
        return tf

    def lookup_why(self, frame: str, stamp: Time | None = None) -> tuple[Transform3 | None, str]:
        fixed = self.fixed_frame
        frame = frame.lstrip("/")
        if not frame:
            return None, "message has an empty frame_id"
        if frame == fixed:
            return Transform3(), ""
        if stamp is not None and stamp.nanoseconds > 0:
            try:
                return self.tf_buffer.lookup_transform(fixed, frame, stamp)[0], ""
            except TransformException:
                pass
        try:
            return self.tf_buffer.lookup_transform(fixed, frame, Time(0))[0], ""
        except TransformException as err:
            return None, f"For frame [{frame}]: {err}"

    # ---------------------------------------------------------- configuration
    def set_config(self, config: DashboardConfig) -> None:
        """Replace the configuration (any thread); applied on the executor thread."""
        self.config = config
        self.config_version += 1
        self.context.executor.call_soon_threadsafe(lambda: self._apply(config))

    def _topic_type(self, display: DisplayConfig) -> str:
        types = DISPLAY_KINDS[display.kind].types
        if len(types) <= 1:
            return types[0] if types else ""
        known = self.topic_types().get(display.topic)
        if known in types:
            return known
        return COMPRESSED_TYPE if display.topic.endswith("/compressed") else types[0]

    def _apply(self, config: DashboardConfig) -> None:
        if config is not self.config:
            return  # a newer configuration is queued behind this one
        pool = list(self.displays)
        fresh: list[DisplayState] = []
        for slot, cfg in enumerate(config.displays):
            key = ("", "")
            if cfg.enabled and cfg.topic and DISPLAY_KINDS[cfg.kind].types:
                key = (cfg.topic, self._topic_type(cfg))
            prev = next((d for d in pool if d.kind == cfg.kind and d.sub_key == key), None)
            if prev is not None:  # same kind on the same topic: keep its data
                pool.remove(prev)
                prev.slot, prev.config = slot, cfg
                self._configure(prev)
                fresh.append(prev)
                continue
            state = DisplayState(slot=slot, config=cfg, sub_key=key)
            self._configure(state)
            if key != ("", ""):
                try:
                    state.sub = self._subscribe(state, key)
                except RoverlabError as err:  # e.g. the topic carries another type
                    state.error = str(err)
            fresh.append(state)
        for d in pool:
            d.sub_key = ("", "")
            if d.sub is not None:
                self.node.destroy_subscription(d.sub)
                d.sub = None
        self.displays = fresh
        self._apply_description(config)

    def _configure(self, state: DisplayState) -> None:
        cfg = state.config
        if cfg.kind == "odometry":
            keep = int(cfg.option("keep"))
            trail = state.trail or PoseTrail()
            trail.keep = keep
            trail.position_tolerance_m = float(cfg.option("position_tolerance"))
            trail.angle_tolerance_rad = float(cfg.option("angle_tolerance"))
            state.trail = trail
        if cfg.kind in ("marker", "marker_array") and state.markers is None:
            state.markers = MarkerStore(self._lookup)

    def _apply_description(self, config: DashboardConfig) -> None:
        robots = [d for d in config.displays if d.kind == "robot_model" and d.enabled]
        topic = robots[0].topic or "/robot_description" if robots else ""
        if topic == self._description_topic:
            return
        if self._description_sub is not None:
            self.node.destroy_subscription(self._description_sub)
            self._description_sub = None
        self._description_topic = topic
        self._description_text = ""
        self.outlines = None
        self.shapes = []
        if topic:
            self._description_sub = self.node.create_subscription(
                "std_msgs/msg/String", topic, self._on_description, _LATCHED
            )
            self._description_from_master(topic)

    def _description_from_master(self, name: str) -> None:
        """On a ROS 1 graph the robot description is the master's parameter of that name
        (as rviz's RobotModel reads it), not a topic: read it from there, and again each
        time it is set (the master's paramUpdate), where the transport can watch it."""
        for transport in self.node.context.transports:
            watch = getattr(transport, "watch_param", None)
            get_param = getattr(transport, "get_param", None)
            if watch is not None:
                text = watch(self.node, name, partial(self._description_param, name))
            elif get_param is not None:
                text = get_param(name, None)
            else:
                continue
            self._description_param(name, text)
            return

    def _description_param(self, name: str, text: Any) -> None:
        if name != self._description_topic or not isinstance(text, str) or not text.strip():
            return
        if text == self._description_text:
            return  # the same text again (our own topic mirrored to the parameter)
        try:
            self._on_description(String(data=text))
        except (RoverlabError, ValueError) as err:
            self.node.get_logger().warning(f"robot description {name}: {err}")

    def _subscribe(self, state: DisplayState, key: tuple[str, str]) -> Any:
        topic, typename = key
        kind = state.kind
        handler = HANDLERS[kind](self)

        def callback(msg: Any) -> None:
            if state.sub_key != key:
                return
            state.received += 1
            state.last_message_s = time.monotonic()
            try:
                handler.on_message(state, msg)
                state.error = None
            except (RoverlabError, ValueError, OSError) as err:
                state.error = f"{type(err).__name__}: {err}"

        qos: QoSProfile | int = _LATCHED if kind == "map" else (1 if kind == "image" else 10)
        state.subscribed_s = time.monotonic()
        return self.node.create_subscription(typename, topic, callback, qos)

    # -------------------------------------------------------------- callbacks
    def _on_clock(self, msg: Any) -> None:
        """A bag played again (or a simulation restarted) sends /clock back in time: the
        dashboard runs on the wall clock, so its TF buffer, holding the end of the last
        play, would ignore every new transform as older than its cache (TF_OLD_DATA) and
        freeze the robot. As rviz does ("Detected jump back in time. Resetting RViz."),
        the transforms and the odometry trails are dropped; maps stay until the next one."""
        now = Time.from_msg(msg.clock).nanoseconds
        last = self._clock_ns
        self._clock_ns = now
        if last is None or now >= last - _JUMP_BACK_NS:
            return
        self.node.get_logger().warning(
            f"Detected jump back in time of {(last - now) / 1e9:f}s. Resetting the dashboard."
        )
        self.tf_buffer.clear()
        for d in self.displays:
            if d.trail is not None:
                d.trail.poses.clear()
                d.trail.full.clear()

    def _refresh_markers(self) -> None:
        now_ns = self.context.now().nanoseconds
        for d in self.displays:
            if d.markers is not None and d.markers.refresh(now_ns):
                markers_changed(self, d)

    def _on_description(self, msg: Any) -> None:
        model = parse_urdf(str(msg.data), source=self._description_topic)
        self._description_text = str(msg.data)
        self.shapes = [shape.to_dict() for shape in robot_shapes(model)]
        self.outlines = Versioned(self.next_version(), robot_outlines(model))
        self.joint_sliders = JointSliders(model)

    def set_joint(self, name: str, position: float) -> None:
        """Move a joint slider and publish every slider on the sliders topic.

        Raises:
            KeyError: no robot description yet, or no such joint.
        """
        if self.joint_sliders is None:
            raise KeyError("no robot description: no joints to move")
        self.joint_sliders.set(name, position)
        if self._slider_pub is None:
            self._slider_pub = self.node.create_publisher(JointState, SLIDER_TOPIC, 10)
        self._slider_pub.publish(self.joint_sliders.message(self.node.get_clock().now().to_msg()))

    # ---------------------------------------------------------------- queries
    def refresh_remote_graph(self) -> None:
        """Ask the other processes for their publishers and subscriptions (blocking)."""
        if self._remote_graph is not None:
            self._remote = list(self._remote_graph())

    def topics(self) -> list[TopicInfo]:
        """Every topic of the running system (this process's and, when attached over the
        network, the others'), with publisher and subscriber counts."""
        pubs: dict[str, int] = {}
        subs: dict[str, int] = {}
        types: dict[str, str] = {}
        for name, t in list(self.context.graph.topics.items()):
            types[name] = t.typename
            pubs[name] = pubs.get(name, 0) + len(t.publishers)
            own = sum(1 for s in t.subscriptions if s.node is self.node)
            subs[name] = subs.get(name, 0) + len(t.subscriptions) - own
        for e in self._remote:
            if e.kind not in ("publisher", "subscription") or not e.topic:
                continue
            types.setdefault(e.topic, e.typename)
            if e.kind == "publisher":
                pubs[e.topic] = pubs.get(e.topic, 0) + 1
            else:
                subs[e.topic] = subs.get(e.topic, 0) + 1
        return [TopicInfo(n, types[n], pubs.get(n, 0), subs.get(n, 0)) for n in sorted(types)]

    def topic_types(self) -> dict[str, str]:
        """Topic -> message type, of the whole system."""
        return {t.name: t.typename for t in self.topics()}

    def image_topics(self) -> list[str]:
        """Topics of type ``sensor_msgs/msg/Image`` or ``CompressedImage`` with a publisher."""
        return sorted(
            t.name
            for t in self.topics()
            if t.typename in (IMAGE_TYPE, COMPRESSED_TYPE) and t.publishers > 0
        )

    def refresh_remote_counts(self) -> None:
        """Ask the other processes how many messages they published per topic (blocking)."""
        if self._remote_counts is None:
            return
        counts = self._remote_counts()
        now = time.monotonic()
        with self._lock:
            for zid, topics in counts.items():
                self._rates.observe(zid, now, topics)

    def topic_rates(self) -> dict[str, float | None]:
        """Messages per wall second of each topic over the last few seconds, counted where
        they are published: by this process's publishers and, attached over the network,
        by the other processes' (:meth:`refresh_remote_counts`); a topic nobody counts (a
        publisher outside roverlab) is measured by the displays subscribed to it. None: not
        measurable."""
        now = time.monotonic()
        local = {n: t.published for n, t in list(self.context.graph.topics.items()) if t.publishers}
        received: dict[str, int] = {}
        for d in self.displays:
            if d.sub_key[0]:
                received[d.sub_key[0]] = received.get(d.sub_key[0], 0) + d.received
        with self._lock:
            self._rates.observe("", now, local)
            self._subscribed_rates.observe("", now, received)
            rates = self._rates.rates(now)
            fallback = self._subscribed_rates.rates(now)
        out: dict[str, float | None] = {}
        for name in list(self.context.graph.topics) + list(rates):
            value = rates.get(name, fallback.get(name))
            out[name] = None if value is None else round(value, 2)
        return out

    def select_image(self, topic: str) -> None:
        """Show ``topic`` in the first image display (created if there is none)."""
        displays = [
            DisplayConfig(d.kind, d.name, d.enabled, d.topic, dict(d.options))
            for d in self.config.displays
        ]
        images = [d for d in displays if d.kind == "image"]
        if images:
            images[0].topic = topic
            images[0].enabled = True
        else:
            displays.append(DisplayConfig("image", "Image", True, topic, {}))
        # the rest (fixed frame, view, Frame Rate, unsupported, source) stays as it was
        self.set_config(dataclasses.replace(self.config, displays=displays))

    def image_frame(self, state: DisplayState) -> Versioned | None:
        """The newest image of an image display as a JPEG/PNG frame (encoded once)."""
        msg = state.image_msg
        if msg is None:
            return None
        cached = state.image_jpeg
        if cached is not None and cached.version == msg.version:
            return cached
        try:
            payload = self._encode_image(state.config, msg.payload)
            state.error = None
        except (RoverlabError, ValueError, OSError) as err:
            state.error = f"cannot show the image: {err}"
            return None
        frame = Versioned(msg.version, payload)
        state.image_jpeg = frame
        return frame

    @staticmethod
    def _encode_image(cfg: DisplayConfig, msg: Any) -> bytes:
        cmap = str(cfg.option("color_map"))
        lo, hi = float(cfg.option("min_value")), float(cfg.option("max_value"))
        if hasattr(msg, "encoding"):
            pixels = image_to_array(msg)
            return encode_image(
                image_to_rgb8(pixels, str(msg.encoding), color_map=cmap, min_value=lo, max_value=hi)
            )
        data = bytes(memoryview(msg.data))
        fmt = str(msg.format).lower()
        if "compresseddepth" in fmt:  # image_transport's compressedDepth: 12-byte header + PNG
            depth = np.asarray(Image.open(io.BytesIO(data[12:])))
            rgb = colorize(depth, cmap, min_value=lo, max_value=hi, invalid_zero=True)
            return encode_image(rgb)
        return encode_image_file(data)

    def state(self, *, with_topics: bool = False) -> dict[str, Any]:
        """Small per-tick state: frames, robot outline, per-display info and status."""
        fixed = self.fixed_frame
        frames: dict[str, list[float]] = {}
        frames3: dict[str, list[float]] = {}
        for name in self.tf_buffer.frames():
            tf = self._lookup(name)
            if tf is not None:
                frames[name] = _xyyaw(tf)
                frames3[name] = [round(float(v), 5) for v in (*tf.translation, *tf.rotation)]
        robot: list[dict[str, Any]] = []
        outlines: list[VisualOutline] = self.outlines.payload if self.outlines else []
        for outline in outlines:
            tf = self._lookup(outline.link)
            if tf is None:
                continue
            poly = outline.footprint(tf)
            robot.append(
                {"rgba": outline.rgba, "points": [[round(x, 4), round(y, 4)] for x, y in poly]}
            )
        out: dict[str, Any] = {
            "type": "state",
            "fixed_frame": fixed,
            "frames": frames,
            "robot": robot,
            "frames3": frames3,
            "robot3d": self.shapes,
            "joints": self.joint_sliders.to_list() if self.joint_sliders else [],
            "displays": [d.info for d in self.displays],
            "status": self.status(frames, outlines),
            "image_topics": self.image_topics(),
            "drive": {"speed": round(self.speed_mps, 4), "turn": round(self.turn_radps, 4)},
            "config_version": self.config_version,
        }
        if with_topics:
            rates = self.topic_rates()
            out["topics"] = [
                {
                    "name": t.name,
                    "type": t.typename,
                    "publishers": t.publishers,
                    "subscribers": t.subscribers,
                    "hz": rates.get(t.name),
                }
                for t in self.topics()
            ]
        return out

    # ------------------------------------------------------------------ tools
    def _header(self) -> dict[str, Any]:
        return {"frame_id": self.fixed_frame, "stamp": stamp_to_msg(self.context.now())}

    def publish_goal(self, x: float, y: float, yaw: float) -> None:
        """2D Nav Goal: a PoseStamped in the fixed frame on ``/move_base_simple/goal``."""
        self.goal_pub.publish(PoseStamped(header=self._header(), pose=pose_from_xytheta(x, y, yaw)))

    def publish_initialpose(self, x: float, y: float, yaw: float) -> None:
        """2D Pose Estimate: ``/initialpose`` with rviz's default covariance."""
        msg = PoseWithCovarianceStamped(
            header=self._header(),
            pose={
                "pose": pose_from_xytheta(x, y, yaw),
                "covariance": np.array(INITIALPOSE_COVARIANCE, dtype=np.float64),
            },
        )
        self.initialpose_pub.publish(msg)

    def publish_point(self, x: float, y: float) -> None:
        """Publish Point: a PointStamped in the fixed frame on ``/clicked_point``."""
        self.point_pub.publish(
            PointStamped(header=self._header(), point={"x": float(x), "y": float(y)})
        )

    def drive_key(self, key: str) -> bool:
        """A teleop key: ``i j l , k u o m .`` (and the holonomic capitals) publish their
        Twist on ``/cmd_vel``; ``q z w x e c`` scale the speeds by 10 % as
        teleop_twist_keyboard does. False if the key means nothing."""
        if key in SPEED_BINDINGS:
            fs, ft = SPEED_BINDINGS[key]
            self.speed_mps *= fs
            self.turn_radps *= ft
            return True
        cmd = twist_for_key(key, self.speed_mps, self.turn_radps)
        if cmd is None:
            return False
        self.cmd_vel_pub.publish(command_to_twist(cmd))
        return True

    def set_speeds(self, speed_mps: float, turn_radps: float) -> None:
        """The drive panel's speed controls (``~speed`` and ``~turn``).

        Raises:
            DashboardError: a speed that is negative or not finite.
        """
        for name, v in (("speed", speed_mps), ("turn", turn_radps)):
            if not (math.isfinite(v) and v >= 0):
                raise DashboardError(f"{name} must be a finite number >= 0, got {v}")
        self.speed_mps, self.turn_radps = speed_mps, turn_radps

    def save_map(self, name: str = "map") -> Path:
        """map_saver of the newest map: ``map_dir/NAME.pgm`` + ``NAME.yaml``.

        The map comes from the first map display on ``/map`` (else the first map display
        with data).

        Raises:
            DashboardError: a bad name, no map received yet, or the files cannot be written.
        """
        if not _MAP_NAME.match(name) or name.startswith("."):
            raise DashboardError(f"bad map name {name!r}: use letters, digits, '_', '-', '.'")
        maps = [d for d in self.displays if d.kind == "map" and d.map_msg is not None]
        maps.sort(key=lambda d: d.config.topic != "/map")
        if not maps:
            raise DashboardError("no map received yet: nothing to save")
        msg = maps[0].map_msg
        o = msg.info.origin
        try:
            saved = save_map(
                self.map_dir / name,
                occupancy_grid_to_array(msg),
                resolution=float(msg.info.resolution),
                origin=(
                    float(o.position.x),
                    float(o.position.y),
                    yaw_from_quaternion(o.orientation),
                ),
            )
        except RoverlabError as err:
            raise DashboardError(f"cannot save the map: {err}") from err
        return saved.yaml_path
