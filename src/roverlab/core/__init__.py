"""The node runtime: Context, Node, Publisher, Subscription, Timer, Executor, Parameters.

The rclpy vocabulary on a deterministic single-threaded executor::

    from roverlab.core import Context
    from roverlab.msgs import Twist

    ctx = Context()                      # sim time, as fast as the CPU allows
    node = ctx.create_node("talker")
    pub = node.create_publisher(Twist, "/cmd_vel", 10)
    node.create_timer(0.1, lambda: pub.publish(Twist(linear_x=0.2)))
    ctx.spin_for(5.0)                    # five simulated seconds
"""

from roverlab.core.context import Context, Transport
from roverlab.core.errors import (
    GraphError,
    InvalidTopicNameError,
    ParameterError,
    ServiceError,
    ServiceUnavailableError,
    TopicTypeError,
    TransportError,
)
from roverlab.core.executor import ClockMode, Executor
from roverlab.core.log import NodeLogger, configure_logging
from roverlab.core.node import Clock, Node, Publisher, Subscription, Timer
from roverlab.core.parameters import (
    Parameter,
    ParameterDescriptor,
    ParameterType,
    SetParametersResult,
    load_parameter_file,
    parameters_for_node,
)
from roverlab.core.qos import QoSProfile
from roverlab.core.services import Client, Future, Service
from roverlab.core.time import Duration, Time

__all__ = [
    "Client",
    "Clock",
    "ClockMode",
    "Context",
    "Duration",
    "Executor",
    "Future",
    "GraphError",
    "InvalidTopicNameError",
    "Node",
    "NodeLogger",
    "Parameter",
    "ParameterDescriptor",
    "ParameterError",
    "ParameterType",
    "Publisher",
    "QoSProfile",
    "Service",
    "ServiceError",
    "ServiceUnavailableError",
    "SetParametersResult",
    "Subscription",
    "Time",
    "Timer",
    "TopicTypeError",
    "Transport",
    "TransportError",
    "configure_logging",
    "load_parameter_file",
    "parameters_for_node",
]
