"""``rplidar_ros``: Slamtec RPLIDAR A-series lidars on the documented serial protocol.

No kept PyPI driver fits (``rplidar`` and ``pyrplidar`` saw their last releases in 2017
and 2019), so the protocol is implemented here: :mod:`~roverlab.drivers.rplidar.protocol`
(requests, descriptors, the node stream), :mod:`~roverlab.drivers.rplidar.scan`
(revolutions to LaserScan numbers, as rplidar_ros), :mod:`~roverlab.drivers.rplidar.device`
(the serial port) and :mod:`roverlab.drivers.rplidar.node` (``rplidarNode``).
"""

from __future__ import annotations

from roverlab.drivers.rplidar.protocol import NODE_DTYPE, NodeDecoder, encode_nodes
from roverlab.drivers.rplidar.scan import Revolutions, ScanData, build_scan

__all__ = ["NODE_DTYPE", "NodeDecoder", "Revolutions", "ScanData", "build_scan", "encode_nodes"]
