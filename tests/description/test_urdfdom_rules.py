"""urdfdom's rules, one test each (the table in docs/urdf.md lists them)."""

from __future__ import annotations

import pytest

from roverlab.description import JointType, Mesh, URDFError, parse_urdf


def robot(body: str) -> str:
    return f'<robot name="r">{body}</robot>'


def vis(material: str, shape: str = '<box size="1 1 1"/>') -> str:
    return f"<visual><geometry>{shape}</geometry>{material}</visual>"


def link(name: str, *visuals: str) -> str:
    return f'<link name="{name}">{"".join(visuals)}</link>'


def fixed(name: str, parent: str, child: str, extra: str = "", kind: str = "fixed") -> str:
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f"{extra}</joint>"
    )


RED = '<material name="red"><color rgba="1 0 0 1"/></material>'


# ------------------------------------------------------------------ materials
def test_robot_level_materials_are_known_before_links_wherever_they_are() -> None:
    m = parse_urdf(robot(link("a", vis('<material name="red"/>')) + RED))
    assert m.links["a"].visuals[0].material.rgba == (1.0, 0.0, 0.0, 1.0)  # type: ignore[union-attr]
    assert m.warnings == ()


def test_material_defined_in_a_visual_is_known_to_later_links() -> None:
    m = parse_urdf(
        robot(link("a", vis(RED)) + link("b", vis('<material name="red"/>')) + fixed("j", "a", "b"))
    )
    assert m.links["b"].visuals[0].material.rgba == (1.0, 0.0, 0.0, 1.0)  # type: ignore[union-attr]
    assert m.materials["red"].rgba == (1.0, 0.0, 0.0, 1.0)


def test_known_material_wins_over_a_visuals_own_colour() -> None:
    blue = '<material name="red"><color rgba="0 0 1 1"/></material>'
    m = parse_urdf(robot(link("a", vis(RED)) + link("b", vis(blue)) + fixed("j", "a", "b")))
    assert m.links["b"].visuals[0].material.rgba == (1.0, 0.0, 0.0, 1.0)  # type: ignore[union-attr]


def test_material_used_before_its_definition_is_accepted_without_colour() -> None:
    m = parse_urdf(
        robot(
            link("a", vis('<material name="red"/>')) + link("b", vis(RED)) + fixed("j", "a", "b")
        ),
        source="bot.urdf",
    )
    # urdfdom: the name-only material becomes the robot's 'red'; b's definition is ignored
    assert m.links["a"].visuals[0].material.rgba is None  # type: ignore[union-attr]
    assert m.links["b"].visuals[0].material.rgba is None  # type: ignore[union-attr]
    assert len(m.warnings) == 1
    assert m.warnings[0].startswith("bot.urdf: <link name='a'>: <visual> #1: material 'red'")
    assert "used before any definition" in m.warnings[0]


def test_visual_material_needs_a_name() -> None:
    with pytest.raises(URDFError, match="must have a name attribute"):
        parse_urdf(robot(link("a", vis('<material><color rgba="1 0 0 1"/></material>'))))


def test_duplicate_robot_level_material_is_an_error() -> None:
    with pytest.raises(URDFError, match="material name 'red' is not unique"):
        parse_urdf(robot(RED + RED + link("a")))


def test_colour_values_are_not_range_checked() -> None:
    m = parse_urdf(robot('<material name="m"><color rgba="2 0 0 1"/></material>' + link("a")))
    assert m.materials["m"].rgba == (2.0, 0.0, 0.0, 1.0)


# ------------------------------------------------------------------ links
def test_multiple_visuals_and_collisions_per_link() -> None:
    col = '<collision><geometry><sphere radius="0.1"/></geometry></collision>'
    m = parse_urdf(robot(f'<link name="a">{vis("")}{vis("")}{col}{col}{col}</link>'))
    assert len(m.links["a"].visuals) == 2 and len(m.links["a"].collisions) == 3


def test_mesh_filename_package_uri_and_scale() -> None:
    shape = '<mesh filename="package://pkg/meshes/x.dae" scale="0.001 0.002 0.003"/>'
    m = parse_urdf(robot(link("a", vis("", shape))))
    assert m.links["a"].visuals[0].geometry == Mesh(
        "package://pkg/meshes/x.dae", (0.001, 0.002, 0.003)
    )
    unscaled = parse_urdf(robot(link("a", vis("", '<mesh filename="x.stl"/>'))))
    assert unscaled.links["a"].visuals[0].geometry == Mesh("x.stl", (1.0, 1.0, 1.0))


def test_geometry_uses_its_first_shape() -> None:
    m = parse_urdf(robot(link("a", vis("", '<sphere radius="1"/><box size="1 1 1"/>'))))
    assert type(m.links["a"].visuals[0].geometry).__name__ == "Sphere"


def test_geometry_without_shape_is_an_error() -> None:
    with pytest.raises(URDFError, match="<geometry> holds no shape"):
        parse_urdf(robot(link("a", vis("", ""))))


# ------------------------------------------------------------------ joints
@pytest.mark.parametrize("kind", ["fixed", "continuous", "floating", "planar"])
def test_joint_types_without_limits(kind: str) -> None:
    m = parse_urdf(robot(link("a") + link("b") + fixed("j", "a", "b", kind=kind)))
    assert m.joints["j"].type is JointType(kind)


@pytest.mark.parametrize("kind", ["revolute", "prismatic"])
def test_revolute_and_prismatic_need_limits(kind: str) -> None:
    with pytest.raises(URDFError, match=f"a {kind} joint needs <limit"):
        parse_urdf(robot(link("a") + link("b") + fixed("j", "a", "b", kind=kind)))


def test_limit_needs_effort_and_velocity_on_any_joint_type() -> None:
    limit = '<limit lower="-1" upper="1" velocity="1"/>'
    with pytest.raises(URDFError, match="<limit> has no 'effort' attribute"):
        parse_urdf(robot(link("a") + link("b") + fixed("j", "a", "b", limit, "continuous")))
    ok = '<limit effort="2" velocity="3"/>'
    m = parse_urdf(robot(link("a") + link("b") + fixed("j", "a", "b", ok, "revolute")))
    lim = m.joints["j"].limit
    assert lim is not None and (lim.lower, lim.upper, lim.effort, lim.velocity) == (0, 0, 2, 3)


def test_mimic_defaults_and_needs_a_joint() -> None:
    body = link("a") + link("b") + link("c") + fixed("j1", "a", "b", kind="continuous")
    m = parse_urdf(robot(body + fixed("j2", "a", "c", '<mimic joint="j1"/>', "continuous")))
    mimic = m.joints["j2"].mimic
    assert mimic is not None and (mimic.joint, mimic.multiplier, mimic.offset) == ("j1", 1, 0)
    with pytest.raises(URDFError, match="<mimic> has no joint attribute"):
        parse_urdf(robot(body + fixed("j2", "a", "c", "<mimic/>", "continuous")))


def test_safety_controller_and_calibration_are_accepted() -> None:
    extra = (
        '<limit lower="-1" upper="1" effort="1" velocity="1"/>'
        '<safety_controller k_velocity="10" soft_lower_limit="-0.9" soft_upper_limit="0.9" '
        'k_position="15"/><calibration rising="0.1"/>'
    )
    m = parse_urdf(robot(link("a") + link("b") + fixed("j", "a", "b", extra, "revolute")))
    s = m.joints["j"].safety
    assert s is not None and (s.k_velocity, s.soft_lower_limit, s.k_position) == (10, -0.9, 15)
    with pytest.raises(URDFError, match="<safety_controller> has no 'k_velocity'"):
        parse_urdf(
            robot(
                link("a")
                + link("b")
                + fixed("j", "a", "b", '<safety_controller soft_lower_limit="0"/>')
            )
        )


# ------------------------------------------------------------------ the tree's root
def test_one_root() -> None:
    with pytest.raises(URDFError, match="root"):
        parse_urdf(robot(link("a") + link("b")))


def test_root_with_inertia_is_kdls_warning() -> None:
    inertial = (
        '<inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/>'
        "</inertial>"
    )
    m = parse_urdf(robot(f'<link name="base_link">{inertial}</link>'), source="b.urdf")
    assert m.warnings == (
        "b.urdf: the root link base_link has an inertia specified in the URDF, but KDL does "
        "not support a root link with an inertia (add a dummy root link such as "
        "base_footprint)",
    )


def test_robot_without_links_is_an_error() -> None:
    with pytest.raises(URDFError, match="no <link> elements"):
        parse_urdf(robot(""))
