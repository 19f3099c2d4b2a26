"""ROS package lookup: search order, package.xml names, URIs, errors."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from roverlab.description import (
    DescriptionError,
    PackageNotFoundError,
    PackagePath,
    find_package,
    package_search_path,
    resolve_uri,
)
from roverlab.packages import BUNDLED_PACKAGES_DIR
from tests.description.conftest import MakePackage


@pytest.mark.parametrize("name", ["mbot_description", "bingda_tutorials", "mycar"])
def test_bundled_packages_are_found(name: str) -> None:
    folder = find_package(name)
    assert folder == BUNDLED_PACKAGES_DIR / name
    assert (folder / "package.xml").is_file()


def test_search_order_env_first_then_bundled_then_extra(
    tmp_path: Path, make_package: MakePackage, monkeypatch: pytest.MonkeyPatch
) -> None:
    rover = make_package("mycar", root=tmp_path / "rover")
    ros = make_package("mycar", root=tmp_path / "ros")
    extra = make_package("only_extra", root=tmp_path / "extra")
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "ros"))
    assert find_package("mycar") == ros
    monkeypatch.setenv(
        "ROVERLAB_PACKAGE_PATH",
        os.pathsep.join([str(tmp_path / "nowhere"), str(tmp_path / "rover")]),
    )
    assert find_package("mycar") == rover
    assert find_package("only_extra", [tmp_path / "extra"]) == extra
    roots = package_search_path([tmp_path / "extra"])
    assert roots == (
        tmp_path / "nowhere",
        tmp_path / "rover",
        tmp_path / "ros",
        BUNDLED_PACKAGES_DIR,
        tmp_path / "extra",
    )


def test_bundled_package_beats_extra_path(tmp_path: Path, make_package: MakePackage) -> None:
    make_package("mycar", root=tmp_path / "extra")
    assert find_package("mycar", [tmp_path / "extra"]) == BUNDLED_PACKAGES_DIR / "mycar"


def test_name_comes_from_package_xml_and_nested_folders_are_crawled(
    tmp_path: Path, make_package: MakePackage
) -> None:
    pkg = make_package("real_name", root=tmp_path / "ws" / "src" / "group", folder="folder_name")
    paths = PackagePath([tmp_path / "ws"])
    assert paths.find("real_name") == pkg
    with pytest.raises(PackageNotFoundError):
        paths.find("folder_name")


def test_unreadable_manifest_falls_back_to_folder_name(tmp_path: Path) -> None:
    pkg = tmp_path / "ws" / "broken_pkg"
    pkg.mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>oops</package>")
    assert find_package("broken_pkg", [tmp_path / "ws"]) == pkg


def test_ignored_and_hidden_folders_are_skipped(tmp_path: Path, make_package: MakePackage) -> None:
    make_package("ignored", root=tmp_path / "ws" / "skip")
    (tmp_path / "ws" / "skip" / "CATKIN_IGNORE").touch()
    make_package("hidden", root=tmp_path / "ws" / ".cache")
    paths = PackagePath([tmp_path / "ws"])
    assert "ignored" not in paths.packages()
    assert "hidden" not in paths.packages()


def test_not_found_is_one_line_listing_the_roots(tmp_path: Path) -> None:
    with pytest.raises(PackageNotFoundError) as info:
        find_package("no_such_pkg", [tmp_path / "extra"])
    msg = str(info.value)
    assert "\n" not in msg
    assert "'no_such_pkg'" in msg
    assert str(BUNDLED_PACKAGES_DIR) in msg
    assert str(tmp_path / "extra") in msg


def test_resolve_uri(tmp_path: Path) -> None:
    assert resolve_uri("package://mycar/config/test.rviz") == (
        BUNDLED_PACKAGES_DIR / "mycar" / "config" / "test.rviz"
    )
    assert resolve_uri("package://mycar/config/test.rviz").is_file()
    assert resolve_uri(f"file://{tmp_path}/a%20b.dae") == tmp_path / "a b.dae"
    assert resolve_uri("meshes/base.stl") == Path("meshes/base.stl")
    with pytest.raises(PackageNotFoundError):
        resolve_uri("package://nope/x.dae")
    with pytest.raises(DescriptionError, match="unsupported URI scheme 'model://'"):
        resolve_uri("model://ground_plane/model.sdf")
    with pytest.raises(DescriptionError, match="no package name"):
        resolve_uri("package:///x.dae")
