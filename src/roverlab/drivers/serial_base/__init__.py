"""A differential base on the ros_arduino_bridge serial protocol (ROSArduinoBridge).

The protocol DIY robots use between a computer and a microcontroller running the motors
and encoders: one ASCII command per line, ``\\r``-terminated, answered with one line:

===========  ======================================  ==================
command      meaning                                 answer
===========  ======================================  ==================
``e``        read both encoders                      ``LEFT RIGHT``
``r``        reset the encoders                      ``OK``
``m L R``    wheel speeds, ticks per 1/30 s frame    ``OK``
``o L R``    raw motor PWM                           ``OK``
``u P:D:I:O`` PID gains                              ``OK``
``b``        the link's baud rate                    ``57600``
===========  ======================================  ==================

:mod:`~roverlab.drivers.serial_base.link` speaks it on a serial port,
:mod:`~roverlab.drivers.serial_base.controller` is ``ros_arduino_python``'s base
controller (set-points, ramp, timeout, odometry from ticks) and
:mod:`roverlab.drivers.serial_base.node` the node (``ros_arduino_python/arduino_node.py``;
seed 002's ``roborts_base/roborts_base_node`` maps to it).
"""

from __future__ import annotations

from roverlab.drivers.serial_base.controller import BaseController, BaseParams
from roverlab.drivers.serial_base.link import ArduinoLink

__all__ = ["ArduinoLink", "BaseController", "BaseParams"]
