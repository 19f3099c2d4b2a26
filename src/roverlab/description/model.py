"""The typed robot model: links, joints, materials, ``<gazebo>`` extensions, tree math.

Frozen dataclasses with URDF's names and SI units (metres, radians, kilograms). A
:class:`RobotModel` checks at construction that its joints form one tree (every joint's
links exist, one root, no link with two parents, no cycle) and answers the questions
``robot_state_publisher`` and a simulator ask: the root link, a link's children, the chain
of joints down to a link, and a link's pose for given joint positions::

    model = load_robot("mycar/urdf/xacro/car.urdf.xacro")
    model.root_link                                   # 'base_footprint'
    model.link_transform("laser").translation[2]      # 0.27
    model.link_transform("left_wheel", {"left_wheel2base_link": 1.0})
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from enum import StrEnum
from functools import cached_property
from types import MappingProxyType
from typing import Final

from roverlab.description.errors import URDFError
from roverlab.description.gazebo_specs import GazeboExtensions
from roverlab.geometry import Transform3

Vec3 = tuple[float, float, float]
RGBA = tuple[float, float, float, float]


# --------------------------------------------------------------------------- geometry
@dataclass(frozen=True, slots=True)
class Box:
    """A box centred on its origin; ``size`` is (x, y, z) in metres."""

    size: Vec3


@dataclass(frozen=True, slots=True)
class Cylinder:
    """A cylinder along its z axis, centred on its origin."""

    radius: float
    length: float


@dataclass(frozen=True, slots=True)
class Sphere:
    radius: float


@dataclass(frozen=True, slots=True)
class Mesh:
    """A mesh file (usually ``package://pkg/meshes/x.dae``; see ``resolve_uri``)."""

    filename: str
    scale: Vec3 = (1.0, 1.0, 1.0)


Geometry = Box | Cylinder | Sphere | Mesh


@dataclass(frozen=True, slots=True)
class Material:
    """A named URDF material: colour (RGBA in [0, 1]) and/or texture file."""

    name: str
    rgba: RGBA | None = None
    texture: str | None = None


@dataclass(frozen=True, slots=True)
class Visual:
    origin: Transform3
    geometry: Geometry
    material: Material | None = None
    name: str | None = None


@dataclass(frozen=True, slots=True)
class Collision:
    origin: Transform3
    geometry: Geometry
    name: str | None = None


@dataclass(frozen=True, slots=True)
class Inertial:
    """Mass (kg) at ``origin`` (the centre of mass frame) and its inertia tensor (kg m^2)."""

    mass: float
    origin: Transform3 = field(default_factory=Transform3)
    ixx: float = 0.0
    ixy: float = 0.0
    ixz: float = 0.0
    iyy: float = 0.0
    iyz: float = 0.0
    izz: float = 0.0


@dataclass(frozen=True, slots=True)
class Link:
    name: str
    inertial: Inertial | None = None
    visuals: tuple[Visual, ...] = ()
    collisions: tuple[Collision, ...] = ()


# --------------------------------------------------------------------------- joints
class JointType(StrEnum):
    """URDF joint types."""

    FIXED = "fixed"
    CONTINUOUS = "continuous"
    REVOLUTE = "revolute"
    PRISMATIC = "prismatic"
    FLOATING = "floating"
    PLANAR = "planar"


MOVABLE_JOINT_TYPES: Final = frozenset(
    {JointType.CONTINUOUS, JointType.REVOLUTE, JointType.PRISMATIC}
)
"""Joints with one position, published from ``/joint_states`` (as robot_state_publisher)."""


@dataclass(frozen=True, slots=True)
class JointLimit:
    """Position limits (rad or m), effort (N m or N) and velocity (rad/s or m/s) limits."""

    lower: float = 0.0
    upper: float = 0.0
    effort: float = 0.0
    velocity: float = 0.0


@dataclass(frozen=True, slots=True)
class JointMimic:
    """``position = multiplier * position(joint) + offset``."""

    joint: str
    multiplier: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True, slots=True)
class JointDynamics:
    damping: float = 0.0
    friction: float = 0.0


@dataclass(frozen=True, slots=True)
class JointSafety:
    """``<safety_controller>``: soft limits (rad or m) and the gains pulling back to them."""

    k_velocity: float
    soft_lower_limit: float = 0.0
    soft_upper_limit: float = 0.0
    k_position: float = 0.0


@dataclass(frozen=True, slots=True)
class Joint:
    """A joint: ``parent_T_child = origin * motion(position)``.

    ``axis`` is a unit vector in the joint frame (URDF's default (1, 0, 0)); a revolute or
    continuous joint rotates about it by the position (rad), a prismatic joint slides
    along it (m). Fixed, floating and planar joints have no single position: their motion
    is the identity here (robot_state_publisher publishes fixed and planar joints as
    static transforms and skips floating ones).
    """

    name: str
    type: JointType
    parent: str
    child: str
    origin: Transform3 = field(default_factory=Transform3)
    axis: Vec3 = (1.0, 0.0, 0.0)
    limit: JointLimit | None = None
    mimic: JointMimic | None = None
    dynamics: JointDynamics | None = None
    safety: JointSafety | None = None

    @property
    def movable(self) -> bool:
        return self.type in MOVABLE_JOINT_TYPES

    def motion(self, position: float) -> Transform3:
        """The joint's own motion at ``position`` (identity for non-movable joints)."""
        if self.type in (JointType.REVOLUTE, JointType.CONTINUOUS):
            s = math.sin(position / 2.0)
            ax, ay, az = self.axis
            return Transform3((0.0, 0.0, 0.0), (ax * s, ay * s, az * s, math.cos(position / 2.0)))
        if self.type is JointType.PRISMATIC:
            ax, ay, az = self.axis
            return Transform3((ax * position, ay * position, az * position))
        return Transform3()

    def transform(self, position: float = 0.0) -> Transform3:
        """``parent_T_child`` at ``position``."""
        if not self.movable:
            return self.origin
        return self.origin * self.motion(position)


# --------------------------------------------------------------------------- robot
@dataclass(frozen=True)
class RobotModel:
    """A robot: links and joints forming one tree, materials and Gazebo extensions.

    Args:
        name: the ``<robot name>``.
        links: links by name, in document order.
        joints: joints by name, in document order.
        materials: the robot's named materials.
        gazebo: what the ``<gazebo>`` tags say.
        source: the file (or ``<string>``) the model came from, used in error messages.
        urdf: the URDF XML the model was parsed from (what ``/robot_description`` holds).
        warnings: what the parser accepted as urdfdom does but reports.

    Raises:
        URDFError: the joints do not form one tree over the links.
    """

    name: str
    links: Mapping[str, Link]
    joints: Mapping[str, Joint]
    materials: Mapping[str, Material] = field(default_factory=dict)
    gazebo: GazeboExtensions = field(default_factory=GazeboExtensions)
    source: str = "<string>"
    urdf: str = field(default="", repr=False, compare=False)
    warnings: tuple[str, ...] = field(default=(), compare=False)
    """What urdfdom accepts but a user should hear about (one line each, naming the file)."""

    def __post_init__(self) -> None:
        object.__setattr__(self, "links", MappingProxyType(dict(self.links)))
        object.__setattr__(self, "joints", MappingProxyType(dict(self.joints)))
        object.__setattr__(self, "materials", MappingProxyType(dict(self.materials)))
        self._check_tree()

    # ------------------------------------------------------------ validation
    def _fail(self, message: str) -> URDFError:
        return URDFError(f"{self.source}: {message}")

    def _check_tree(self) -> None:
        if not self.links:
            raise self._fail(f"robot '{self.name}' has no <link> elements")
        parent_of: dict[str, Joint] = {}
        for j in self.joints.values():
            where = f"<joint name='{j.name}'>"
            if j.parent not in self.links:
                raise self._fail(f"{where}: parent link '{j.parent}' is not defined")
            if j.child not in self.links:
                raise self._fail(f"{where}: child link '{j.child}' is not defined")
            if j.parent == j.child:
                raise self._fail(f"{where}: link '{j.child}' is its own parent (a cycle)")
            other = parent_of.get(j.child)
            if other is not None:
                raise self._fail(
                    f"{where}: link '{j.child}' already has parent joint '{other.name}'"
                )
            parent_of[j.child] = j
            if j.mimic is not None:
                target = self.joints.get(j.mimic.joint)
                if target is None or target.name == j.name:
                    raise self._fail(f"{where}: <mimic joint='{j.mimic.joint}'> is not a joint")
        roots = [name for name in self.links if name not in parent_of]
        if len(roots) > 1:
            listed = " and ".join(f"'{r}'" for r in roots[:2])
            more = f" (and {len(roots) - 2} more)" if len(roots) > 2 else ""
            raise self._fail(
                f"two root links found: {listed}{more}; every link but one needs a parent joint"
            )
        if not roots:
            raise self._fail("no root link found: the joints form a cycle")
        reached = {roots[0]}
        stack = [roots[0]]
        children: dict[str, list[str]] = {}
        for j in self.joints.values():
            children.setdefault(j.parent, []).append(j.child)
        while stack:
            for c in children.get(stack.pop(), []):
                if c not in reached:
                    reached.add(c)
                    stack.append(c)
        if len(reached) != len(self.links):
            loop = sorted(set(self.links) - reached)
            names = ", ".join(f"'{n}'" for n in loop)
            raise self._fail(f"the joints form a cycle through links {names}")

    # ------------------------------------------------------------ tree
    @cached_property
    def _parent_joint(self) -> Mapping[str, Joint]:
        return {j.child: j for j in self.joints.values()}

    @cached_property
    def _child_joints(self) -> Mapping[str, tuple[Joint, ...]]:
        out: dict[str, list[Joint]] = {name: [] for name in self.links}
        for j in self.joints.values():
            out[j.parent].append(j)
        return {k: tuple(v) for k, v in out.items()}

    @cached_property
    def root_link(self) -> str:
        """The one link that is no joint's child."""
        return next(name for name in self.links if name not in self._parent_joint)

    def _link(self, link: str) -> str:
        if link not in self.links:
            raise KeyError(f"robot '{self.name}' has no link '{link}'")
        return link

    def parent_joint(self, link: str) -> Joint | None:
        """The joint whose child is ``link`` (None for the root)."""
        return self._parent_joint.get(self._link(link))

    def child_joints(self, link: str) -> tuple[Joint, ...]:
        """Joints whose parent is ``link``, in document order."""
        return self._child_joints[self._link(link)]

    def children(self, link: str) -> tuple[str, ...]:
        """Child links of ``link``, in document order of their joints."""
        return tuple(j.child for j in self.child_joints(link))

    def chain(self, tip: str, root: str | None = None) -> tuple[Joint, ...]:
        """Joints from ``root`` (default: the root link) down to ``tip``, root first.

        Raises:
            KeyError: an unknown link, or ``root`` is not an ancestor of ``tip``.
        """
        base = self.root_link if root is None else self._link(root)
        joints: list[Joint] = []
        link = self._link(tip)
        while link != base:
            j = self._parent_joint.get(link)
            if j is None:
                raise KeyError(f"link '{base}' is not an ancestor of link '{tip}'")
            joints.append(j)
            link = j.parent
        return tuple(reversed(joints))

    @cached_property
    def movable_joints(self) -> tuple[Joint, ...]:
        """Revolute, continuous and prismatic joints, in document order."""
        return tuple(j for j in self.joints.values() if j.movable)

    @cached_property
    def fixed_joints(self) -> tuple[Joint, ...]:
        """Joints published as static transforms: fixed and planar (as KDL treats them)."""
        return tuple(
            j for j in self.joints.values() if j.type in (JointType.FIXED, JointType.PLANAR)
        )

    def joint_position(self, joint: Joint | str, positions: Mapping[str, float]) -> float:
        """A joint's position from ``positions`` (0 if absent); mimic joints follow theirs."""
        j = self.joints[joint] if isinstance(joint, str) else joint
        if j.mimic is not None:
            return j.mimic.multiplier * positions.get(j.mimic.joint, 0.0) + j.mimic.offset
        return positions.get(j.name, 0.0)

    def link_transform(
        self,
        link: str,
        joint_positions: Mapping[str, float] | None = None,
        *,
        root: str | None = None,
    ) -> Transform3:
        """``root_T_link``: the pose of ``link`` in ``root`` (default: the root link).

        Args:
            link: the link whose pose is wanted.
            joint_positions: joint name -> position (rad or m); missing joints are at 0.
            root: an ancestor link to express the pose in.
        """
        positions = joint_positions or {}
        result = Transform3()
        for j in self.chain(link, root):
            result = result * j.transform(self.joint_position(j, positions))
        return result

    def link_transforms(
        self, joint_positions: Mapping[str, float] | None = None
    ) -> dict[str, Transform3]:
        """Every link's pose in the root link frame."""
        positions = joint_positions or {}
        out = {self.root_link: Transform3()}
        stack = [self.root_link]
        while stack:
            parent = stack.pop()
            for j in self._child_joints[parent]:
                out[j.child] = out[parent] * j.transform(self.joint_position(j, positions))
                stack.append(j.child)
        return out
