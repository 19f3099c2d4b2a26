"""Message constructors named like the ROS types: ``Twist(linear_x=0.2)``.

Each factory (a :class:`MessageFactory`) builds a rosbags dataclass instance with every field
defaulted: numbers 0 / 0.0 / False, strings ``''``, nested messages their defaults, sequences
empty numpy arrays (or lists of strings / messages), fixed arrays zeros of their length
(``covariance`` is a float64 array of 36 zeros). Keyword arguments set fields:

* by exact field name, with nested messages given as messages or as dicts:
  ``Twist(linear={"x": 0.2})``;
* by a flattened name joining nested field names with ``_``:
  ``Twist(linear_x=0.2, angular_z=0.5)``, ``PoseStamped(header_frame_id="map")``. A name is
  matched exactly first, then by the longest prefix that names a nested message field;
* number sequences as lists, tuples or numpy arrays, converted to the field's dtype
  (``LaserScan(ranges=[1, 2]).ranges`` is float32). An array of the exact dtype is stored
  as is, not copied; uint8 fields also take ``bytes``.

``isinstance(msg, Twist)`` works; for mypy narrowing use ``isinstance(msg, Twist.cls)``.
Constants of a type are attributes of its factory (``Marker.ARROW``,
``GoalStatus.STATUS_SUCCEEDED``). Short names shared by two packages resolve as in
:mod:`.classes` (``GoalStatus`` is ``action_msgs``). Any other type of the store is built with
:func:`make` or :func:`get_factory`.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping
from typing import Any, Final, Generic, TypeVar

from . import classes as mc
from ._store import STORE, FieldKind, TypeSpec
from ._values import coerce_field, default_makers, default_message, from_dict, unknown_field

T = TypeVar("T")


@functools.lru_cache(maxsize=4096)
def _flat_head(typename: str, key: str) -> str | None:
    """The nested message field that a flattened ``key`` starts with, or ``None``.

    ``pose_position_x`` in ``PoseStamped`` gives ``pose``. Longer field names are tried first
    and the rest of the key must resolve inside the nested type.
    """
    spec = STORE.spec(typename)
    heads = sorted(
        (f for f in spec.fields if f.kind is FieldKind.MESSAGE and key.startswith(f.name + "_")),
        key=lambda f: -len(f.name),
    )
    for head in heads:
        rest = key[len(head.name) + 1 :]
        if rest in STORE.spec(head.typename).by_name or _flat_head(head.typename, rest):
            return head.name
    return None


def _fields_of(msg: Any, spec: TypeSpec) -> dict[str, Any]:
    return {f.name: getattr(msg, f.attr) for f in spec.by_name.values()}


def build_message(spec: TypeSpec, fields: Mapping[str, Any], label: str, path: str = "") -> Any:
    """Build a message of type ``spec`` from keyword fields (exact or flattened names).

    Args:
        spec: The type.
        fields: Field values by exact or flattened name.
        label: How errors name the top type (``'Twist'``).
        path: Dotted path of this message inside the top one.

    Raises:
        FieldError: A name is neither a field nor a flattened path of the type.
        MessageValueError: A value has the wrong kind.
    """
    if not fields:
        return default_message(spec)
    direct: dict[str, Any] = {}
    nested: dict[str, dict[str, Any]] = {}
    for key, value in fields.items():
        if key in spec.by_name:
            direct[key] = value
            continue
        head = _flat_head(spec.typename, key)
        if head is None:
            raise unknown_field(label, spec, f"{path}.{key}" if path else key, key)
        nested.setdefault(head, {})[key[len(head) + 1 :]] = value
    values = []
    for f, make in zip(spec.fields, default_makers(spec)[1], strict=True):
        name = f.name
        if nested and name in nested:
            sub_path = f"{path}.{name}" if path else name
            sub_spec = STORE.spec(f.typename)
            base = direct.get(name)
            if base is None:
                merged: dict[str, Any] = {}
            elif isinstance(base, Mapping):
                merged = dict(base)
            else:
                merged = _fields_of(coerce_field(f, base, label, sub_path), sub_spec)
            merged.update(nested[name])
            values.append(build_message(sub_spec, merged, label, sub_path))
        elif name in direct:
            values.append(coerce_field(f, direct[name], label, f"{path}.{name}" if path else name))
        else:
            values.append(make())
    return spec.cls(*values)


class MessageFactory(Generic[T]):
    """Constructor with defaults for one message type; calling it builds a message.

    Args:
        cls: The rosbags dataclass of the type.

    Attributes:
        cls: The rosbags dataclass (instances are what the factory builds).
        typename: Full ROS 2 type name, ``geometry_msgs/msg/Twist``.
        short_name: ``Twist``.
    """

    __slots__ = ("_label", "_spec", "cls", "short_name", "typename")

    def __init__(self, cls: type[T]) -> None:
        spec = STORE.spec(cls)
        if spec.cls is not cls:
            raise TypeError(f"{cls!r} is not the store's class for {spec.typename}")
        self.cls: Final[type[T]] = cls
        self.typename: Final[str] = spec.typename
        self.short_name: Final[str] = spec.short
        self._spec = spec
        self._label = f"{spec.short!r}"

    @property
    def __msgtype__(self) -> str:
        """The full type name (the rosbags convention, so a factory is accepted as a type)."""
        return self.typename

    @property
    def fields(self) -> tuple[str, ...]:
        """ROS field names in definition order."""
        return tuple(self._spec.by_name)

    @property
    def constants(self) -> dict[str, Any]:
        """Constants of the type by name (``{'ARROW': 0, ...}``)."""
        return dict(self._spec.constants)

    def __call__(self, **fields: Any) -> T:
        """Build a message; see the module docstring for the accepted keyword forms.

        Raises:
            FieldError: Unknown field (``'Twist' has no field 'linaer'``).
            MessageValueError: Wrong kind of value.
        """
        msg: T = build_message(self._spec, fields, self._label)
        return msg

    def from_dict(self, data: Mapping[str, Any]) -> T:
        """Build a message from a nested dict of ROS field names (see :func:`from_dict`)."""
        msg: T = from_dict(self._spec.typename, data)
        return msg

    def __instancecheck__(self, obj: object) -> bool:
        return isinstance(obj, self.cls)

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_"):
            raise AttributeError(name)
        try:
            return self._spec.constants[name]
        except KeyError:
            raise AttributeError(
                f"message factory {self.short_name!r} has no attribute or constant {name!r}"
            ) from None

    def __dir__(self) -> list[str]:
        return sorted({*super().__dir__(), *self._spec.constants})

    def __repr__(self) -> str:
        return f"<message factory {self.typename}>"


_FACTORIES: dict[str, MessageFactory[Any]] = {}


def factory_for(cls: type[T]) -> MessageFactory[T]:
    """The (shared) factory of a rosbags message class."""
    found = _FACTORIES.get(cls.__msgtype__)  # type: ignore[attr-defined]
    if found is None:
        found = MessageFactory(cls)
        _FACTORIES[found.typename] = found
    return found


def get_factory(typename: object) -> MessageFactory[Any]:
    """The factory of any type of the store, given by name (any form), class or message.

    Raises:
        UnknownTypeError: Unknown type.
    """
    return factory_for(STORE.spec(typename).cls)


def make(typename: object, **fields: Any) -> Any:
    """Build a message of any type of the store, as the factories do.

    Example: ``make("nav_msgs/Odometry", child_frame_id="base_link", pose_pose_position_x=1.0)``.

    Raises:
        UnknownTypeError: Unknown type.
        FieldError: Unknown field.
        MessageValueError: Wrong kind of value.
    """
    return get_factory(typename)(**fields)


# builtin_interfaces
Time: Final[MessageFactory[mc.Time]] = factory_for(mc.Time)
Duration: Final[MessageFactory[mc.Duration]] = factory_for(mc.Duration)

# std_msgs
Header: Final[MessageFactory[mc.Header]] = factory_for(mc.Header)
String: Final[MessageFactory[mc.String]] = factory_for(mc.String)
Bool: Final[MessageFactory[mc.Bool]] = factory_for(mc.Bool)
Byte: Final[MessageFactory[mc.Byte]] = factory_for(mc.Byte)
Char: Final[MessageFactory[mc.Char]] = factory_for(mc.Char)
Empty: Final[MessageFactory[mc.Empty]] = factory_for(mc.Empty)
ColorRGBA: Final[MessageFactory[mc.ColorRGBA]] = factory_for(mc.ColorRGBA)
Float32: Final[MessageFactory[mc.Float32]] = factory_for(mc.Float32)
Float64: Final[MessageFactory[mc.Float64]] = factory_for(mc.Float64)
Int8: Final[MessageFactory[mc.Int8]] = factory_for(mc.Int8)
Int16: Final[MessageFactory[mc.Int16]] = factory_for(mc.Int16)
Int32: Final[MessageFactory[mc.Int32]] = factory_for(mc.Int32)
Int64: Final[MessageFactory[mc.Int64]] = factory_for(mc.Int64)
UInt8: Final[MessageFactory[mc.UInt8]] = factory_for(mc.UInt8)
UInt16: Final[MessageFactory[mc.UInt16]] = factory_for(mc.UInt16)
UInt32: Final[MessageFactory[mc.UInt32]] = factory_for(mc.UInt32)
UInt64: Final[MessageFactory[mc.UInt64]] = factory_for(mc.UInt64)
Float32MultiArray: Final[MessageFactory[mc.Float32MultiArray]] = factory_for(mc.Float32MultiArray)
Float64MultiArray: Final[MessageFactory[mc.Float64MultiArray]] = factory_for(mc.Float64MultiArray)
MultiArrayLayout: Final[MessageFactory[mc.MultiArrayLayout]] = factory_for(mc.MultiArrayLayout)
MultiArrayDimension: Final[MessageFactory[mc.MultiArrayDimension]] = factory_for(
    mc.MultiArrayDimension
)

# geometry_msgs
Point: Final[MessageFactory[mc.Point]] = factory_for(mc.Point)
Point32: Final[MessageFactory[mc.Point32]] = factory_for(mc.Point32)
PointStamped: Final[MessageFactory[mc.PointStamped]] = factory_for(mc.PointStamped)
Quaternion: Final[MessageFactory[mc.Quaternion]] = factory_for(mc.Quaternion)
QuaternionStamped: Final[MessageFactory[mc.QuaternionStamped]] = factory_for(mc.QuaternionStamped)
Vector3: Final[MessageFactory[mc.Vector3]] = factory_for(mc.Vector3)
Vector3Stamped: Final[MessageFactory[mc.Vector3Stamped]] = factory_for(mc.Vector3Stamped)
Pose: Final[MessageFactory[mc.Pose]] = factory_for(mc.Pose)
Pose2D: Final[MessageFactory[mc.Pose2D]] = factory_for(mc.Pose2D)
PoseStamped: Final[MessageFactory[mc.PoseStamped]] = factory_for(mc.PoseStamped)
PoseWithCovariance: Final[MessageFactory[mc.PoseWithCovariance]] = factory_for(
    mc.PoseWithCovariance
)
PoseWithCovarianceStamped: Final[MessageFactory[mc.PoseWithCovarianceStamped]] = factory_for(
    mc.PoseWithCovarianceStamped
)
PoseArray: Final[MessageFactory[mc.PoseArray]] = factory_for(mc.PoseArray)
Twist: Final[MessageFactory[mc.Twist]] = factory_for(mc.Twist)
TwistStamped: Final[MessageFactory[mc.TwistStamped]] = factory_for(mc.TwistStamped)
TwistWithCovariance: Final[MessageFactory[mc.TwistWithCovariance]] = factory_for(
    mc.TwistWithCovariance
)
TwistWithCovarianceStamped: Final[MessageFactory[mc.TwistWithCovarianceStamped]] = factory_for(
    mc.TwistWithCovarianceStamped
)
Accel: Final[MessageFactory[mc.Accel]] = factory_for(mc.Accel)
AccelStamped: Final[MessageFactory[mc.AccelStamped]] = factory_for(mc.AccelStamped)
AccelWithCovariance: Final[MessageFactory[mc.AccelWithCovariance]] = factory_for(
    mc.AccelWithCovariance
)
AccelWithCovarianceStamped: Final[MessageFactory[mc.AccelWithCovarianceStamped]] = factory_for(
    mc.AccelWithCovarianceStamped
)
Wrench: Final[MessageFactory[mc.Wrench]] = factory_for(mc.Wrench)
WrenchStamped: Final[MessageFactory[mc.WrenchStamped]] = factory_for(mc.WrenchStamped)
Transform: Final[MessageFactory[mc.Transform]] = factory_for(mc.Transform)
TransformStamped: Final[MessageFactory[mc.TransformStamped]] = factory_for(mc.TransformStamped)
Polygon: Final[MessageFactory[mc.Polygon]] = factory_for(mc.Polygon)
PolygonStamped: Final[MessageFactory[mc.PolygonStamped]] = factory_for(mc.PolygonStamped)

# sensor_msgs
LaserScan: Final[MessageFactory[mc.LaserScan]] = factory_for(mc.LaserScan)
Imu: Final[MessageFactory[mc.Imu]] = factory_for(mc.Imu)
Image: Final[MessageFactory[mc.Image]] = factory_for(mc.Image)
CompressedImage: Final[MessageFactory[mc.CompressedImage]] = factory_for(mc.CompressedImage)
CameraInfo: Final[MessageFactory[mc.CameraInfo]] = factory_for(mc.CameraInfo)
RegionOfInterest: Final[MessageFactory[mc.RegionOfInterest]] = factory_for(mc.RegionOfInterest)
PointCloud2: Final[MessageFactory[mc.PointCloud2]] = factory_for(mc.PointCloud2)
PointField: Final[MessageFactory[mc.PointField]] = factory_for(mc.PointField)
JointState: Final[MessageFactory[mc.JointState]] = factory_for(mc.JointState)
Range: Final[MessageFactory[mc.Range]] = factory_for(mc.Range)
NavSatFix: Final[MessageFactory[mc.NavSatFix]] = factory_for(mc.NavSatFix)
NavSatStatus: Final[MessageFactory[mc.NavSatStatus]] = factory_for(mc.NavSatStatus)
Joy: Final[MessageFactory[mc.Joy]] = factory_for(mc.Joy)
BatteryState: Final[MessageFactory[mc.BatteryState]] = factory_for(mc.BatteryState)
MagneticField: Final[MessageFactory[mc.MagneticField]] = factory_for(mc.MagneticField)
Temperature: Final[MessageFactory[mc.Temperature]] = factory_for(mc.Temperature)

# nav_msgs
Odometry: Final[MessageFactory[mc.Odometry]] = factory_for(mc.Odometry)
OccupancyGrid: Final[MessageFactory[mc.OccupancyGrid]] = factory_for(mc.OccupancyGrid)
MapMetaData: Final[MessageFactory[mc.MapMetaData]] = factory_for(mc.MapMetaData)
Path: Final[MessageFactory[mc.Path]] = factory_for(mc.Path)
GridCells: Final[MessageFactory[mc.GridCells]] = factory_for(mc.GridCells)

# tf2_msgs
TFMessage: Final[MessageFactory[mc.TFMessage]] = factory_for(mc.TFMessage)

# rosgraph_msgs
Clock: Final[MessageFactory[mc.Clock]] = factory_for(mc.Clock)

# visualization_msgs
Marker: Final[MessageFactory[mc.Marker]] = factory_for(mc.Marker)
MarkerArray: Final[MessageFactory[mc.MarkerArray]] = factory_for(mc.MarkerArray)

# action_msgs
GoalInfo: Final[MessageFactory[mc.GoalInfo]] = factory_for(mc.GoalInfo)
GoalStatus: Final[MessageFactory[mc.GoalStatus]] = factory_for(mc.GoalStatus)
GoalStatusArray: Final[MessageFactory[mc.GoalStatusArray]] = factory_for(mc.GoalStatusArray)

# unique_identifier_msgs
UUID: Final[MessageFactory[mc.UUID]] = factory_for(mc.UUID)

# diagnostic_msgs
DiagnosticArray: Final[MessageFactory[mc.DiagnosticArray]] = factory_for(mc.DiagnosticArray)
DiagnosticStatus: Final[MessageFactory[mc.DiagnosticStatus]] = factory_for(mc.DiagnosticStatus)
KeyValue: Final[MessageFactory[mc.KeyValue]] = factory_for(mc.KeyValue)

# rcl_interfaces
Log: Final[MessageFactory[mc.Log]] = factory_for(mc.Log)

#: Full names of the types exposed as module-level factories, in declaration order.
EXPOSED_TYPES: Final[tuple[str, ...]] = tuple(
    f.typename
    for f in (
        Time,
        Duration,
        Header,
        String,
        Bool,
        Byte,
        Char,
        Empty,
        ColorRGBA,
        Float32,
        Float64,
        Int8,
        Int16,
        Int32,
        Int64,
        UInt8,
        UInt16,
        UInt32,
        UInt64,
        Float32MultiArray,
        Float64MultiArray,
        MultiArrayLayout,
        MultiArrayDimension,
        Point,
        Point32,
        PointStamped,
        Quaternion,
        QuaternionStamped,
        Vector3,
        Vector3Stamped,
        Pose,
        Pose2D,
        PoseStamped,
        PoseWithCovariance,
        PoseWithCovarianceStamped,
        PoseArray,
        Twist,
        TwistStamped,
        TwistWithCovariance,
        TwistWithCovarianceStamped,
        Accel,
        AccelStamped,
        AccelWithCovariance,
        AccelWithCovarianceStamped,
        Wrench,
        WrenchStamped,
        Transform,
        TransformStamped,
        Polygon,
        PolygonStamped,
        LaserScan,
        Imu,
        Image,
        CompressedImage,
        CameraInfo,
        RegionOfInterest,
        PointCloud2,
        PointField,
        JointState,
        Range,
        NavSatFix,
        NavSatStatus,
        Joy,
        BatteryState,
        MagneticField,
        Temperature,
        Odometry,
        OccupancyGrid,
        MapMetaData,
        Path,
        GridCells,
        TFMessage,
        Clock,
        Marker,
        MarkerArray,
        GoalInfo,
        GoalStatus,
        GoalStatusArray,
        UUID,
        DiagnosticArray,
        DiagnosticStatus,
        KeyValue,
        Log,
    )
)
