"""The ``arduino`` node (``ros_arduino_python/arduino_node.py``): a differential base on
ROSArduinoBridge firmware.

Parameters (ros_arduino_python's names and defaults): ``port`` (``/dev/ttyUSB0``),
``baud`` (57600), ``timeout`` (0.5 s per command), ``rate`` / ``sensorstate_rate``
(accepted: the sensors are not implemented), ``use_base_controller`` (false: then nothing
is driven), ``base_frame`` (``base_link``), ``publish_odom_base_transform`` (true), and the
base controller's (see :mod:`roverlab.drivers.serial_base.controller`).

Subscribes ``cmd_vel`` (geometry_msgs/Twist); publishes ``odom`` (nav_msgs/Odometry, frame
``odom``, child ``base_frame``, covariance as ros_arduino_python's) and the ``odom ->
base_frame`` transform at ``base_controller_rate``. A thread polls the board: ``e`` for the
counts, ``m L R`` for the speeds. Unreadable answers (garbage) are skipped and reported at
most every 5 s; a board that does not answer for a second, or a missing port, is one error
line: the thread reconnects every second (keeping the pose) and says when the board is
back. On shutdown the wheels are stopped (``m 0 0``).
"""

from __future__ import annotations

import contextlib
import functools
import threading
from typing import Any, Final

from roverlab.core import Context, Node
from roverlab.drivers.errors import DeviceError, DriverError
from roverlab.drivers.odometry import odometry_messages
from roverlab.drivers.serial_base.controller import BaseController, BaseParams
from roverlab.drivers.serial_base.link import ArduinoLink
from roverlab.msgs import classes as mc
from roverlab.tf import TransformBroadcaster

__all__ = ["ArduinoBaseNode"]

SILENCE_S: Final = 1.0
RETRY_S: Final = 1.0
_GARBAGE_REPORT_S: Final = 5.0
_POSE_COVARIANCE: Final = [0.0] * 36
for _i, _v in ((0, 0.1), (7, 0.1), (14, 1e6), (21, 1e6), (28, 1e6), (35, 0.2)):
    _POSE_COVARIANCE[_i] = _v


class ArduinoBaseNode(Node):
    """arduino_node.py's base controller on a ROSArduinoBridge board.

    Args:
        context: the context the node joins.
        node_name: defaults to ``arduino``.
        boot_wait_s: how long a (re)connection waits for the board to answer.
        **node_kwargs: ``namespace``, ``parameter_overrides``, ``remappings``.

    Raises:
        DriverError: a missing or invalid base geometry parameter.
    """

    def __init__(
        self,
        context: Context,
        *,
        node_name: str = "arduino",
        boot_wait_s: float = 2.0,
        **node_kwargs: Any,
    ) -> None:
        super().__init__(node_name, context=context, **node_kwargs)
        p = self.declare_parameter
        self.port = str(p("port", "/dev/ttyUSB0").value)
        self.baud = int(p("baud", 57600).value)
        self.timeout = float(p("timeout", 0.5).value)
        p("rate", 50.0)
        p("sensorstate_rate", 10.0)
        use_base = bool(p("use_base_controller", False).value)
        self.base_frame = str(p("base_frame", "base_link").value)
        self.publish_tf = bool(p("publish_odom_base_transform", True).value)
        p("use_imu_heading", False)
        geometry = {k: p(k, 0.0).value for k in ("wheel_diameter", "wheel_track")}
        geometry["encoder_resolution"] = p("encoder_resolution", 0).value
        missing = [k for k, v in geometry.items() if not v]
        if use_base and missing:
            raise DriverError(f"base controller parameter(s) missing: {', '.join(missing)}")
        self.params = BaseParams(
            wheel_diameter=float(geometry["wheel_diameter"] or 1.0),
            wheel_track=float(geometry["wheel_track"] or 1.0),
            encoder_resolution=float(geometry["encoder_resolution"] or 1.0),
            gear_reduction=float(p("gear_reduction", 1.0).value),
            base_controller_rate=float(p("base_controller_rate", 10.0).value),
            base_controller_timeout=float(p("base_controller_timeout", 1.0).value),
            accel_limit=float(p("accel_limit", 1.0).value),
            motors_reversed=bool(p("motors_reversed", False).value),
            odom_linear_scale_correction=float(p("odom_linear_scale_correction", 1.0).value),
            odom_angular_scale_correction=float(p("odom_angular_scale_correction", 1.0).value),
            Kp=int(p("Kp", 20).value),
            Kd=int(p("Kd", 12).value),
            Ki=int(p("Ki", 0).value),
            Ko=int(p("Ko", 50).value),
        )
        self.controller = BaseController(self.params, now_s=self._now_s())
        self._lock = threading.Lock()
        self._odom_pub = self.create_publisher(mc.Odometry, "odom", 5)
        self._tf = TransformBroadcaster(self)
        self.create_subscription(mc.Twist, "cmd_vel", self._on_cmd_vel, 10)
        self.bad_answers = 0
        self.polls = 0
        self._boot_wait_s = boot_wait_s
        self._stop = threading.Event()
        self._last_error = ""
        self._thread = threading.Thread(target=self._run, name=f"arduino {self.port}", daemon=True)
        if use_base:
            self.get_logger().info(
                f"Started base controller for a base of {self.params.wheel_track}m wide with "
                f"{self.params.encoder_resolution} ticks per rev; publishing odometry at "
                f"{self.params.base_controller_rate} Hz using {self.base_frame} as base frame"
            )
            self._thread.start()
        else:
            self.get_logger().warning("use_base_controller is false: the base is not driven")

    def _now_s(self) -> float:
        return self.get_clock().now_ns() / 1e9

    def _on_cmd_vel(self, msg: mc.Twist) -> None:
        try:
            with self._lock:
                self.controller.command(
                    float(msg.linear.x), float(msg.angular.z), now_s=self._now_s()
                )
        except DriverError as err:
            self.get_logger().warning(f"{err}; ignored")

    # ----------------------------------------------------------------- thread
    def _report(self, message: str) -> None:
        if message != self._last_error:
            self.get_logger().error(message)
            self._last_error = message

    def _run(self) -> None:
        first = True
        while not self._stop.is_set():
            link = ArduinoLink(self.port, self.baud, timeout_s=self.timeout)
            try:
                link.open(boot_wait_s=self._boot_wait_s)
                p = self.params
                link.update_pid(p.Kp, p.Kd, p.Ki, p.Ko)
                if first:
                    link.reset_encoders()  # "Clear any old odometry info"
                    first = False
                with self._lock:
                    self.controller.odometry.rebase()
                if self._last_error:
                    self.get_logger().info(f"{self.port}: the board answers again")
                    self._last_error = ""
                self._poll(link)
            except DeviceError as err:
                self._report(f"{err}; retrying every {RETRY_S:g} s")
            finally:
                if link.is_open:
                    with contextlib.suppress(DeviceError):
                        link.drive(0, 0)
                link.close()
            self._stop.wait(RETRY_S)

    def _poll(self, link: ArduinoLink) -> None:
        period = 1.0 / self.params.base_controller_rate
        failing_since: float | None = None
        last_garbage_report = -_GARBAGE_REPORT_S
        while not self._stop.wait(period):
            now = self._now_s()
            try:
                left, right = link.get_encoder_counts()
            except DeviceError as err:
                mono = self.get_clock().now_ns() / 1e9
                failing_since = mono if failing_since is None else failing_since
                if "no answer" in str(err) and mono - failing_since >= SILENCE_S:
                    raise DeviceError(
                        f"{self.port}: the board stopped answering (nothing for {SILENCE_S:g} s)"
                    ) from err
                if "unreadable" in str(err):
                    self.bad_answers += 1
                    if mono - last_garbage_report >= _GARBAGE_REPORT_S:
                        self.get_logger().warning(f"{err} (skipped)")
                        last_garbage_report = mono
                continue
            failing_since = None
            with self._lock:
                state, out_l, out_r = self.controller.update(left, right, now)
            now_ns = int(now * 1e9)
            self.context.executor.call_soon_threadsafe(
                functools.partial(self._publish, state, now_ns)
            )
            self.polls += 1
            try:
                link.drive(out_l, out_r)
            except DeviceError as err:
                if "no answer" in str(err):
                    raise
                self.bad_answers += 1

    def _publish(self, state: Any, stamp_ns: int) -> None:
        odom, tf = odometry_messages(
            state,
            stamp_ns=stamp_ns,
            odom_frame="odom",
            base_frame=self.base_frame,
            pose_covariance=_POSE_COVARIANCE,
        )
        if self.publish_tf:
            self._tf.send_transform(tf)
        self._odom_pub.publish(odom)

    def destroy_node(self) -> None:
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(timeout=3.0)
        super().destroy_node()
