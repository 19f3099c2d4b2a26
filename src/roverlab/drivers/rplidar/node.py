"""The ``rplidarNode`` node (``rplidar_ros/rplidarNode``): RPLIDAR A-series scans.

Parameters (rplidar_ros's names and defaults): ``serial_port`` (``/dev/ttyUSB0``),
``serial_baudrate`` (115200; 256000 for an A3), ``frame_id`` (``laser_frame``),
``inverted`` (false), ``angle_compensate`` (false), ``scan_mode`` (empty or
``Standard``: the standard scan, the one mode implemented), ``scan_frequency`` (10 Hz: for
the angle-compensation grid; the motor turns as the device does), ``channel_type``
(``serial``; ``tcp`` / ``udp`` are not implemented).

Publishes ``scan`` (sensor_msgs/LaserScan, see :mod:`roverlab.drivers.rplidar.scan`) once
per revolution; ``scan_time`` is the revolution's nodes times the device's sample period
(GET_SAMPLERATE) and the stamp that long before the revolution was complete; services
``stop_motor`` and ``start_motor`` (std_srvs/Empty).

A reader thread talks to the device: STOP, GET_INFO, GET_HEALTH (an Error status is
refused, as rplidar_ros does), GET_SAMPLERATE, motor on, SCAN, then nodes. A missing port,
a device that stops answering for a second, or a port that fails is one error line; the
thread closes the port and tries again every second, and says when the device is back.
Garbage on the line is skipped (counted, reported at most once per reconnection).
"""

from __future__ import annotations

import threading
from typing import Any, Final

from roverlab.core import Context, Node, ParameterError
from roverlab.drivers.errors import DeviceError, DriverError
from roverlab.drivers.rplidar.device import DEFAULT_MOTOR_PWM, RplidarDevice
from roverlab.drivers.rplidar.protocol import NodeDecoder
from roverlab.drivers.rplidar.scan import Revolutions, ScanData, build_scan
from roverlab.msgs import classes as mc

__all__ = ["RplidarNode"]

SILENCE_S: Final = 1.0
"""No byte for this long while scanning: the device stopped answering."""
RETRY_S: Final = 1.0
_MAX_DISTANCE_M: Final = 12.0  # A1/A2 standard mode range


class RplidarNode(Node):
    """rplidarNode: an RPLIDAR on a serial port, scans on ``scan``.

    Args:
        context: the context the node joins.
        node_name: defaults to ``rplidarNode``.
        **node_kwargs: ``namespace``, ``parameter_overrides``, ``remappings``.

    Raises:
        DriverError: an unsupported ``channel_type`` or ``scan_mode``.
        ParameterError: a non-positive baud rate or scan frequency.
    """

    def __init__(self, context: Context, *, node_name: str = "rplidarNode", **node_kwargs: Any):
        super().__init__(node_name, context=context, **node_kwargs)
        p = self.declare_parameter
        channel = str(p("channel_type", "serial").value)
        self.serial_port = str(p("serial_port", "/dev/ttyUSB0").value)
        self.baudrate = int(p("serial_baudrate", 115200).value)
        self.frame_id = str(p("frame_id", "laser_frame").value)
        self.inverted = bool(p("inverted", False).value)
        self.angle_compensate = bool(p("angle_compensate", False).value)
        scan_mode = str(p("scan_mode", "").value)
        self.scan_frequency = float(p("scan_frequency", 10.0).value)
        for name, default in (("tcp_ip", "192.168.0.7"), ("tcp_port", 20108)):
            p(name, default)
        if channel != "serial":
            raise DriverError(f"channel_type {channel!r}: only serial is implemented")
        if scan_mode not in ("", "Standard"):
            raise DriverError(
                f"scan mode `{scan_mode}' is not supported: roverlab implements Standard"
            )
        if self.baudrate <= 0 or not self.scan_frequency > 0:
            raise ParameterError(f"{node_name}: serial_baudrate and scan_frequency must be > 0")
        self._pub = self.create_publisher(mc.LaserScan, "scan", 1000)
        self.create_service("std_srvs/srv/Empty", "stop_motor", self._on_stop_motor)
        self.create_service("std_srvs/srv/Empty", "start_motor", self._on_start_motor)
        self.scans_published = 0
        self.dropped_bytes = 0
        self.us_per_sample = 0.0
        self._motor = threading.Event()
        self._motor.set()
        self._stop = threading.Event()
        self._last_error = ""
        self._thread = threading.Thread(
            target=self._run, name=f"rplidar {self.serial_port}", daemon=True
        )
        self._thread.start()

    # ----------------------------------------------------------------- services
    def _on_stop_motor(self, _request: Any, response: Any) -> Any:
        self._motor.clear()
        return response

    def _on_start_motor(self, _request: Any, response: Any) -> Any:
        self._motor.set()
        return response

    # ----------------------------------------------------------------- reader thread
    def _report(self, message: str) -> None:
        if message != self._last_error:
            self.get_logger().error(message)
            self._last_error = message

    def _run(self) -> None:
        while not self._stop.is_set():
            device = RplidarDevice(self.serial_port, self.baudrate)
            try:
                device.open()
                self._session(device)
            except DeviceError as err:
                self._report(f"{err}; retrying every {RETRY_S:g} s")
            finally:
                if device.is_open:
                    try:
                        device.stop()
                        device.set_motor(0)
                    except DeviceError:
                        pass
                device.close()
            self._stop.wait(RETRY_S)

    def _session(self, device: RplidarDevice) -> None:
        device.stop()
        info = device.get_info()
        health = device.get_health()
        if health.status == 2:
            raise DeviceError(
                f"{self.serial_port}: rplidar internal error detected (code "
                f"{health.error_code}); reboot the device"
            )
        self.us_per_sample = float(device.get_samplerate()[0])
        if self._last_error:
            self.get_logger().info(f"{self.serial_port}: the device answers again")
            self._last_error = ""
        self.get_logger().info(
            f"RPLIDAR MODE:{info.model_name} S/N: {info.serial_number} Firmware Ver: "
            f"{info.firmware[0]}.{info.firmware[1]:02d} Hardware Rev: {info.hardware}; "
            f"health status : {health.name}; current scan mode: Standard, sample rate: "
            f"{1000 / self.us_per_sample:.0f} Khz, scan frequency:{self.scan_frequency:.1f} Hz"
        )
        while not self._stop.is_set():
            if not self._motor.is_set():
                device.stop()
                device.set_motor(0)
                while not self._motor.is_set() and not self._stop.is_set():
                    self._stop.wait(0.05)
                continue
            device.set_motor(DEFAULT_MOTOR_PWM)
            device.start_scan()
            self._stream(device)

    def _stream(self, device: RplidarDevice) -> None:
        decoder = NodeDecoder()
        revolutions = Revolutions()
        reported = 0
        while self._motor.is_set() and not self._stop.is_set():
            data = device.read(SILENCE_S)
            now_ns = self.get_clock().now_ns()
            for rev in revolutions.push(decoder.feed(data)):
                self._hand_over(rev, now_ns)
            self.dropped_bytes += decoder.dropped_bytes - reported
            if decoder.dropped_bytes and not reported:
                self.get_logger().warning(
                    f"{self.serial_port}: skipped unreadable bytes in the scan stream"
                )
            reported = decoder.dropped_bytes

    def _hand_over(self, rev: Any, end_ns: int) -> None:
        """Publish a revolution completed at ``end_ns``: it took its nodes times the
        device's sample period (the device's clock, not the host's reads, which come in
        bursts), so it started that long before."""
        scan = build_scan(
            rev,
            angle_compensate=self.angle_compensate,
            inverted=self.inverted,
            us_per_sample=self.us_per_sample,
            scan_frequency_hz=self.scan_frequency,
            max_distance_m=_MAX_DISTANCE_M,
        )
        if scan is not None:
            duration = len(rev) * self.us_per_sample * 1e-6
            start_ns = end_ns - int(duration * 1e9)
            self.context.executor.call_soon_threadsafe(
                lambda: self._publish(scan, start_ns, duration)
            )

    def _publish(self, scan: ScanData, stamp_ns: int, duration_s: float) -> None:
        n = len(scan.ranges)
        sec, nanosec = divmod(stamp_ns, 1_000_000_000)
        self._pub.publish(
            mc.LaserScan(
                header=mc.Header(mc.Time(sec, nanosec), self.frame_id),
                angle_min=float(scan.angle_min),
                angle_max=float(scan.angle_max),
                angle_increment=float(scan.angle_increment),
                time_increment=duration_s / (n - 1) if n > 1 else 0.0,
                scan_time=duration_s,
                range_min=scan.range_min,
                range_max=scan.range_max,
                ranges=scan.ranges,
                intensities=scan.intensities,
            )
        )
        self.scans_published += 1

    def destroy_node(self) -> None:
        self._stop.set()
        self._thread.join(timeout=3.0)
        super().destroy_node()
