"""Device drivers: the ROS driver nodes of real robots' hardware, and simulated stand-ins.

One sub-package per ROS driver package, each a pure part (protocols, controllers,
odometry: no bus, no clock) and a thin ``node.py``:

* :mod:`roverlab.drivers.arbotix`: ``arbotix_python``'s ``arbotix_driver`` with its
  ``diff_controller`` (``sim: true`` drives a fake base);
* :mod:`roverlab.drivers.usb_cam`: ``usb_cam``'s ``usb_cam_node`` through OpenCV;
* :mod:`roverlab.drivers.rplidar`: ``rplidar_ros``'s ``rplidarNode`` on the RPLIDAR
  serial protocol;
* :mod:`roverlab.drivers.serial_base`: a differential base on the ros_arduino_bridge
  serial protocol (``ros_arduino_python``'s ``arduino_node.py``; seed 002's
  ``roborts_base`` maps to it).

:mod:`roverlab.drivers.odometry` holds what the base drivers share: wheel set-points,
acceleration ramps and odometry from encoder ticks.
"""

from __future__ import annotations

from roverlab.drivers.errors import DeviceError, DriverError

__all__ = ["DeviceError", "DriverError"]
