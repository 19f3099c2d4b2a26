"""Loading robots: URDF / xacro files and strings -> :class:`RobotModel`.

:func:`load_robot` accepts a ``.urdf`` file, a ``.xacro`` / ``.urdf.xacro`` file, or the XML
itself. Files ending in ``.xacro`` (and any document declaring ``xmlns:xacro``) go through
xacro first, with ``$(find pkg)`` resolved through the package path. The URDF is then
checked the way ``check_urdf`` (urdfdom) checks it, and every problem is one
:class:`URDFError` line naming the file and the element: bad XML (with its line number), no
``<robot>``, a joint whose link does not exist, two roots, a cycle, duplicate names, a
negative or NaN size, an unknown geometry or joint type, a revolute joint without limits, a
``<limit>`` without effort or velocity, a visual material without a name, a Gazebo sensor
on a missing link, a drive plugin naming a missing joint.

Materials follow urdfdom's rules exactly (docs/urdf.md lists them): the robot-level
``<material>`` elements are known first, wherever they are; then, link by link in document
order, each visual's material is the known one of that name if there is one (its own colour
is then ignored), else the visual's own definition, which becomes known to every later link.
A name used before any definition is accepted as urdfdom accepts it (a material without
colour) and reported in :attr:`RobotModel.warnings`.
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from collections.abc import Iterable, Mapping
from pathlib import Path

from roverlab.description.errors import URDFError
from roverlab.description.gazebo import parse_gazebo
from roverlab.description.gazebo_specs import DiffDriveSpec, ImuPluginSpec
from roverlab.description.model import (
    Box,
    Collision,
    Cylinder,
    Geometry,
    Inertial,
    Joint,
    JointDynamics,
    JointLimit,
    JointMimic,
    JointSafety,
    JointType,
    Link,
    Material,
    Mesh,
    RobotModel,
    Sphere,
    Visual,
)
from roverlab.description.packages import PackagePath
from roverlab.description.xacro_hook import xacro_file, xacro_string
from roverlab.geometry import Transform3, quat_from_rpy

PathOrXML = str | os.PathLike[str]
_JOINT_TYPES = {t.value: t for t in JointType}


# --------------------------------------------------------------------------- values
class _Ctx:
    """Error messages prefixed with the source and an element path."""

    def __init__(self, source: str, where: str) -> None:
        self.source = source
        self.where = where

    def sub(self, what: str) -> _Ctx:
        return _Ctx(self.source, f"{self.where}: {what}" if self.where else what)

    def fail(self, problem: str) -> URDFError:
        where = f"{self.where}: " if self.where else ""
        return URDFError(f"{self.source}: {where}{problem}")

    def floats(
        self, elem: ET.Element, attr: str, n: int, default: tuple[float, ...] | None
    ) -> tuple[float, ...]:
        raw = elem.get(attr)
        if raw is None:
            if default is None:
                raise self.fail(f"<{elem.tag}> has no '{attr}' attribute")
            return default
        try:
            values = tuple(float(p) for p in raw.split())
        except ValueError:
            raise self.fail(f"<{elem.tag} {attr}='{raw}'>: not {n} number(s)") from None
        if len(values) != n:
            raise self.fail(f"<{elem.tag} {attr}='{raw}'>: expected {n} number(s)")
        if not all(math.isfinite(v) for v in values):
            raise self.fail(f"<{elem.tag} {attr}='{raw}'>: NaN or infinite value")
        return values

    def number(self, elem: ET.Element, attr: str, default: float | None = None) -> float:
        return self.floats(elem, attr, 1, None if default is None else (default,))[0]

    def size(self, elem: ET.Element, attr: str, n: int = 1) -> tuple[float, ...]:
        values = self.floats(elem, attr, n, None)
        if any(v < 0 for v in values):
            raise self.fail(f"<{elem.tag} {attr}='{elem.get(attr)}'>: negative size")
        return values


def _vec3(values: tuple[float, ...]) -> tuple[float, float, float]:
    return (values[0], values[1], values[2])


def _origin(elem: ET.Element | None, ctx: _Ctx) -> Transform3:
    if elem is None:
        return Transform3()
    xyz = ctx.floats(elem, "xyz", 3, (0.0, 0.0, 0.0))
    rpy = ctx.floats(elem, "rpy", 3, (0.0, 0.0, 0.0))
    return Transform3.from_arrays(xyz, quat_from_rpy(*rpy))


def _geometry(elem: ET.Element | None, ctx: _Ctx) -> Geometry:
    if elem is None:
        raise ctx.fail("no <geometry>")
    shapes = [c for c in elem if isinstance(c.tag, str)]
    if not shapes:
        raise ctx.fail("<geometry> holds no shape (box, cylinder, sphere or mesh)")
    shape = shapes[0]  # urdfdom reads the first child element only
    g = ctx.sub("<geometry>")
    if shape.tag == "box":
        return Box(_vec3(g.size(shape, "size", 3)))
    if shape.tag == "cylinder":
        return Cylinder(radius=g.size(shape, "radius")[0], length=g.size(shape, "length")[0])
    if shape.tag == "sphere":
        return Sphere(radius=g.size(shape, "radius")[0])
    if shape.tag == "mesh":
        filename = shape.get("filename", "").strip()
        if not filename:
            raise g.fail("<mesh> has no filename")
        scale = g.floats(shape, "scale", 3, (1.0, 1.0, 1.0))
        return Mesh(filename, _vec3(scale))
    raise g.fail(f"unknown geometry <{shape.tag}> (use box, cylinder, sphere or mesh)")


def _material(elem: ET.Element, ctx: _Ctx) -> Material:
    name = elem.get("name", "")
    m = ctx.sub(f"<material name='{name}'>")
    rgba = None
    color = elem.find("color")
    if color is not None:
        values = m.floats(color, "rgba", 4, None)
        # urdfdom does not range-check colours; renderers clamp them
        rgba = (values[0], values[1], values[2], values[3])
    texture = elem.find("texture")
    tex = texture.get("filename") if texture is not None else None
    return Material(name=name, rgba=rgba, texture=tex)


def _inertial(elem: ET.Element, ctx: _Ctx) -> Inertial:
    c = ctx.sub("<inertial>")
    mass_elem = elem.find("mass")
    if mass_elem is None:
        raise c.fail("no <mass>")
    mass = c.number(mass_elem, "value")
    if mass < 0:
        raise c.fail(f"<mass value='{mass_elem.get('value')}'>: negative mass")
    inertia = elem.find("inertia")
    if inertia is None:
        raise c.fail("no <inertia>")
    i = {k: c.number(inertia, k) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
    return Inertial(mass=mass, origin=_origin(elem.find("origin"), c), **i)


def _link(
    elem: ET.Element,
    ctx: _Ctx,
    materials: dict[str, Material],
    warnings: list[str],
) -> Link:
    name = elem.get("name", "")
    c = ctx.sub(f"<link name='{name}'>")
    inertial_elem = elem.find("inertial")
    inertial = _inertial(inertial_elem, c) if inertial_elem is not None else None
    visuals: list[Visual] = []
    for k, v in enumerate(elem.findall("visual"), start=1):
        vc = c.sub(f"<visual> #{k}")
        material = None
        m_elem = v.find("material")
        if m_elem is not None:
            if m_elem.get("name") is None:
                raise vc.fail(
                    "<material> must have a name attribute (urdfdom: 'Visual material "
                    "must contain a name attribute')"
                )
            local = _material(m_elem, vc)
            # urdfdom's assignMaterial: a known material of that name wins; else the
            # visual's own one (even without colour) becomes known to every later link.
            material = materials.get(local.name)
            if material is None:
                if local.rgba is None and local.texture is None:
                    warnings.append(
                        vc.fail(
                            f"material '{local.name}' is used before any definition: urdfdom "
                            "gives it no colour and later definitions of that name are ignored"
                        ).args[0]
                    )
                material = local
                materials[local.name] = local
        visuals.append(
            Visual(
                origin=_origin(v.find("origin"), vc),
                geometry=_geometry(v.find("geometry"), vc),
                material=material,
                name=v.get("name"),
            )
        )
    collisions = []
    for k, col in enumerate(elem.findall("collision"), start=1):
        cc = c.sub(f"<collision> #{k}")
        collisions.append(
            Collision(
                origin=_origin(col.find("origin"), cc),
                geometry=_geometry(col.find("geometry"), cc),
                name=col.get("name"),
            )
        )
    return Link(name, inertial, tuple(visuals), tuple(collisions))


def _joint(elem: ET.Element, ctx: _Ctx) -> Joint:
    name = elem.get("name", "")
    c = ctx.sub(f"<joint name='{name}'>")
    raw_type = elem.get("type")
    if raw_type is None:
        raise c.fail("no type attribute")
    jtype = _JOINT_TYPES.get(raw_type)
    if jtype is None:
        raise c.fail(f"unknown joint type '{raw_type}' (use {', '.join(_JOINT_TYPES)})")
    links = {}
    for role in ("parent", "child"):
        e = elem.find(role)
        link = e.get("link", "").strip() if e is not None else ""
        if not link:
            raise c.fail(f"no <{role} link='...'>")
        links[role] = link
    axis = (1.0, 0.0, 0.0)
    axis_elem = elem.find("axis")
    if axis_elem is not None:
        raw = c.floats(axis_elem, "xyz", 3, (1.0, 0.0, 0.0))
        norm = math.sqrt(sum(v * v for v in raw))
        if norm < 1e-12:
            if jtype in (JointType.REVOLUTE, JointType.CONTINUOUS, JointType.PRISMATIC):
                raise c.fail(f"<axis xyz='{axis_elem.get('xyz')}'>: zero axis")
        else:
            axis = (raw[0] / norm, raw[1] / norm, raw[2] / norm)
    limit = None
    limit_elem = elem.find("limit")
    if limit_elem is not None:
        lc = c.sub("<limit>")  # urdfdom: effort and velocity always, lower/upper default 0
        limit = JointLimit(
            lower=lc.number(limit_elem, "lower", 0.0),
            upper=lc.number(limit_elem, "upper", 0.0),
            effort=lc.number(limit_elem, "effort"),
            velocity=lc.number(limit_elem, "velocity"),
        )
    elif jtype in (JointType.REVOLUTE, JointType.PRISMATIC):
        raise c.fail(f"a {jtype.value} joint needs <limit lower upper effort velocity>")
    mimic = None
    mimic_elem = elem.find("mimic")
    if mimic_elem is not None:
        target = mimic_elem.get("joint", "").strip()
        if not target:
            raise c.fail("<mimic> has no joint attribute")
        mimic = JointMimic(
            joint=target,
            multiplier=c.number(mimic_elem, "multiplier", 1.0),
            offset=c.number(mimic_elem, "offset", 0.0),
        )
    dynamics = None
    dyn = elem.find("dynamics")
    if dyn is not None:
        dynamics = JointDynamics(c.number(dyn, "damping", 0.0), c.number(dyn, "friction", 0.0))
    safety = None
    safe = elem.find("safety_controller")
    if safe is not None:
        sc = c.sub("<safety_controller>")
        safety = JointSafety(
            k_velocity=sc.number(safe, "k_velocity"),
            soft_lower_limit=sc.number(safe, "soft_lower_limit", 0.0),
            soft_upper_limit=sc.number(safe, "soft_upper_limit", 0.0),
            k_position=sc.number(safe, "k_position", 0.0),
        )
    calibration = elem.find("calibration")
    if calibration is not None:
        for attr in ("rising", "falling"):
            if calibration.get(attr) is not None:
                c.sub("<calibration>").number(calibration, attr)
    return Joint(
        name=name,
        type=jtype,
        parent=links["parent"],
        child=links["child"],
        origin=_origin(elem.find("origin"), c),
        axis=axis,
        limit=limit,
        mimic=mimic,
        dynamics=dynamics,
        safety=safety,
    )


def _strip_namespaces(root: ET.Element) -> None:
    for e in root.iter():
        if isinstance(e.tag, str) and e.tag.startswith("{"):
            e.tag = e.tag.split("}", 1)[1]


def _unique(kind: str, names: Iterable[str], ctx: _Ctx) -> None:
    seen: set[str] = set()
    for n in names:
        if not n:
            raise ctx.fail(f"a <{kind}> has no name")
        if n in seen:
            raise ctx.fail(f"{kind} name '{n}' is not unique")
        seen.add(n)


# --------------------------------------------------------------------------- API
def parse_urdf(xml_text: str, *, source: str = "<string>") -> RobotModel:
    """Parse and check a URDF document (no xacro processing).

    Args:
        xml_text: the URDF XML.
        source: the file name used in error messages.

    Raises:
        URDFError: one line naming ``source`` and the element at fault.
    """
    try:
        root = ET.fromstring(xml_text)
    except ET.ParseError as err:
        raise URDFError(f"{source}: XML parse error: {err}") from err
    _strip_namespaces(root)
    ctx = _Ctx(source, "")
    if root.tag != "robot":
        raise ctx.fail(f"no <robot> element (the document's root is <{root.tag}>)")
    name = root.get("name", "").strip()
    if not name:
        raise ctx.fail("<robot> has no name attribute")
    materials: dict[str, Material] = {}
    mat_elems = root.findall("material")
    _unique("material", (m.get("name", "") for m in mat_elems), ctx)
    for m in mat_elems:
        materials[m.get("name", "")] = _material(m, ctx)
    link_elems = root.findall("link")
    joint_elems = root.findall("joint")
    _unique("link", (e.get("name", "") for e in link_elems), ctx)
    _unique("joint", (e.get("name", "") for e in joint_elems), ctx)
    warnings: list[str] = []
    for name_, mat in materials.items():
        if mat.rgba is None and mat.texture is None:
            warnings.append(
                ctx.fail(f"<material name='{name_}'> has no <color> or <texture>").args[0]
            )
    links = {e.get("name", ""): _link(e, ctx, materials, warnings) for e in link_elems}
    joints = {e.get("name", ""): _joint(e, ctx) for e in joint_elems}
    gazebo = parse_gazebo(root.findall("gazebo"), source, model_name=name)
    model = RobotModel(
        name=name,
        links=links,
        joints=joints,
        materials=materials,
        gazebo=gazebo,
        source=source,
        urdf=xml_text,
        warnings=tuple(warnings),
    )
    root_link = model.links[model.root_link]
    if root_link.inertial is not None:  # robot_state_publisher's KDL parser warns so
        object.__setattr__(
            model,
            "warnings",
            (
                *model.warnings,
                f"{source}: the root link {root_link.name} has an inertia specified in the URDF, "
                "but KDL does not support a root link with an inertia (add a dummy root link "
                "such as base_footprint)",
            ),
        )
    _check_gazebo(model, ctx)
    return model


def _check_gazebo(model: RobotModel, ctx: _Ctx) -> None:
    for s in model.gazebo.sensors:
        if s.reference_link not in model.links:
            raise ctx.fail(
                f"<gazebo reference='{s.reference_link}'>: <sensor name='{s.name}'> "
                f"is on link '{s.reference_link}', which is not defined"
            )
    for p in model.gazebo.plugins:
        where = f"<plugin name='{p.name}' filename='{p.filename}'>"
        if isinstance(p.spec, DiffDriveSpec):
            roles = [("leftJoint", p.spec.left_joint), ("rightJoint", p.spec.right_joint)]
            if p.spec.rear_joints is not None:  # skid steer: Gazebo throws on a missing one
                roles = [
                    ("leftFrontJoint", p.spec.left_joint),
                    ("rightFrontJoint", p.spec.right_joint),
                    ("leftRearJoint", p.spec.rear_joints[0]),
                    ("rightRearJoint", p.spec.rear_joints[1]),
                ]
            for role, joint in roles:
                j = model.joints.get(joint)
                if j is None or not j.movable:
                    raise ctx.fail(f"{where}: <{role}> '{joint}' is not a movable joint")
        elif isinstance(p.spec, ImuPluginSpec) and p.spec.body_name not in model.links:
            raise ctx.fail(f"{where}: <bodyName> '{p.spec.body_name}' is not a link")


def _is_xml(value: PathOrXML) -> bool:
    return isinstance(value, str) and value.lstrip().startswith("<")


def robot_description(
    path_or_xml: PathOrXML,
    args: Mapping[str, str] | None = None,
    *,
    package_path: Iterable[str | os.PathLike[str]] = (),
    xacro_ns: bool = False,
) -> str:
    """The URDF XML a launch file would put in the ``robot_description`` parameter.

    A xacro file (``.xacro`` suffix, or any file declaring ``xmlns:xacro``) is expanded as
    ``xacro file name:=value ...`` prints it; a plain URDF is returned as it is.

    Raises:
        XacroError: the xacro expansion failed.
        URDFError: the file cannot be read.
    """
    packages = PackagePath(package_path)
    if _is_xml(path_or_xml):
        text = str(path_or_xml)
        if "xmlns:xacro" in text:
            return xacro_string(text, args=args, package_path=packages, xacro_ns=xacro_ns)
        return text
    path = Path(path_or_xml)
    if path.suffix == ".xacro":
        return xacro_file(path, args=args, package_path=packages, xacro_ns=xacro_ns)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as err:
        raise URDFError(f"{path}: cannot read: {err.strerror or err}") from err
    except UnicodeDecodeError as err:
        raise URDFError(f"{path}: not a UTF-8 text file") from err
    if "xmlns:xacro" in text:
        return xacro_file(path, args=args, package_path=packages, xacro_ns=xacro_ns)
    return text


def load_robot(
    path_or_xml: PathOrXML,
    *,
    args: Mapping[str, str] | None = None,
    package_path: Iterable[str | os.PathLike[str]] = (),
    xacro_ns: bool = False,
    source: str | None = None,
) -> RobotModel:
    """Load a robot from a ``.urdf`` / ``.xacro`` / ``.urdf.xacro`` file or an XML string.

    Args:
        path_or_xml: a file path, or the document itself (a string starting with ``<``).
        args: xacro arguments, ``{"laser_visual": "true"}`` for ``laser_visual:=true``.
        package_path: extra folders where ``$(find pkg)`` looks (after the environment
            and the bundled packages).
        source: where a document given as a string came from (the file a launch's
            ``<param command="xacro FILE">`` read), named in the model's messages
            instead of ``<string>``.

    Raises:
        XacroError: the xacro expansion failed.
        URDFError: the robot is not valid.
    """
    if not _is_xml(path_or_xml):
        source = str(path_or_xml)
    xml_text = robot_description(path_or_xml, args, package_path=package_path, xacro_ns=xacro_ns)
    return parse_urdf(xml_text, source=source or "<string>")
