"""The ``map_server`` and ``map_saver`` nodes: thin wrappers of :mod:`roverlab.maps.map_io`.

MapServer (ROS 1 ``map_server``)
    loads ``NAME.yaml`` and publishes the map once, latched, on ``map``
    (``nav_msgs/OccupancyGrid``) and ``map_metadata`` (``nav_msgs/MapMetaData``), stamped
    with the load time, in frame ``frame_id``; the ``static_map`` service
    (``nav_msgs/GetMap``) answers with the same map.

MapSaver (ROS 1 ``map_saver -f NAME``)
    waits for one message on ``map`` and writes ``NAME.pgm`` and ``NAME.yaml``, reporting
    as map_saver does ("Waiting for the map", "Received a W X H map @ R m/pix", ...).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from roverlab.core import Context, Node, QoSProfile
from roverlab.maps.errors import MapError
from roverlab.maps.map_io import (
    ImageFormat,
    OccupancyMap,
    check_save_thresholds,
    load_map,
    save_occupancy_grid,
)
from roverlab.msgs import MapMetaData, OccupancyGrid

__all__ = ["MapSaver", "MapServer"]

_LATCHED = QoSProfile(depth=1, durability="transient_local")


class MapServer(Node):
    """Publishes a map file on ``map`` and ``map_metadata`` (latched).

    Args:
        context: the context the node joins.
        yaml_path: the map's YAML file (map_server's argument).
        frame_id: default of the ``frame_id`` parameter.
        node_name: defaults to ``map_server``.
        **node_kwargs: ``namespace``, ``parameter_overrides``, ``remappings`` of
            :class:`~roverlab.core.Node`.

    Parameters:
        frame_id (string, "map"): frame of the published map.

    Raises:
        MapError: the map cannot be loaded.
    """

    def __init__(
        self,
        context: Context,
        *,
        yaml_path: str | os.PathLike[str],
        frame_id: str = "map",
        node_name: str = "map_server",
        **node_kwargs: Any,
    ) -> None:
        super().__init__(node_name, context=context, **node_kwargs)
        self.frame_id = str(self.declare_parameter("frame_id", frame_id).value)
        self.map: OccupancyMap = load_map(yaml_path)
        self.map_msg = self.map.to_msg(frame_id=self.frame_id, stamp=self.get_clock().now())
        self.metadata_msg = self.map_msg.info
        self.metadata_publisher = self.create_publisher(MapMetaData, "map_metadata", _LATCHED)
        self.map_publisher = self.create_publisher(OccupancyGrid, "map", _LATCHED)
        self.metadata_publisher.publish(self.metadata_msg)
        self.map_publisher.publish(self.map_msg)
        self.static_map_service = self.create_service(
            "nav_msgs/GetMap", "static_map", self._on_static_map
        )
        self.get_logger().info(
            f"Read a {self.map.width} X {self.map.height} map @ "
            f"{self.map.info.resolution:.3f} m/cell"
        )

    def _on_static_map(self, _request: Any, response: Any) -> Any:
        response.map = self.map_msg
        return response


class MapSaver(Node):
    """Saves the first map it receives, as ``map_saver -f NAME``, then ends itself (as
    map_saver's process exits): ``exit_code`` 0 when saved, 1 when writing failed.

    Args:
        context: the context the node joins.
        path_prefix: output name without extension (``-f``, default ``map``).
        map_topic: the topic to read (``map``).
        threshold_occupied: cells ``>=`` this become black (``--occ``, 1..100).
        threshold_free: cells ``0..`` this become white (``--free``, 0..100).
        image_format: ``pgm`` (map_saver) or ``png``.
        report: called with each progress line; by default they go to the node's logger.
        node_name: defaults to ``map_saver``.
        **node_kwargs: ``namespace``, ``parameter_overrides``, ``remappings``.

    Attributes:
        done: a map was saved.
        saved_paths: ``(image, yaml)`` paths once saved.
        error: why saving failed (the node has then ended too), or None.

    Raises:
        MapError: bad thresholds.
    """

    def __init__(
        self,
        context: Context,
        *,
        path_prefix: str | os.PathLike[str] = "map",
        map_topic: str = "map",
        threshold_occupied: int = 65,
        threshold_free: int = 25,
        image_format: ImageFormat = "pgm",
        report: Callable[[str], None] | None = None,
        node_name: str = "map_saver",
        **node_kwargs: Any,
    ) -> None:
        check_save_thresholds(threshold_occupied, threshold_free)
        super().__init__(node_name, context=context, **node_kwargs)
        self.path_prefix = os.fspath(path_prefix)
        self.threshold_occupied = threshold_occupied
        self.threshold_free = threshold_free
        self.image_format: ImageFormat = image_format
        self.done = False
        self.saved_paths: tuple[Path, Path] | None = None
        self.error: MapError | None = None
        self._logged = report is None
        self._report = report if report is not None else self.get_logger().info
        self._report("Waiting for the map")
        self._subscription = self.create_subscription(
            OccupancyGrid, map_topic, self._on_map, _LATCHED
        )

    @property
    def finished(self) -> bool:
        """Saved, or failed to."""
        return self.done or self.error is not None

    def _on_map(self, msg: Any) -> None:
        if self.finished:
            return
        info = msg.info
        prefix = self.path_prefix
        self._report(
            f"Received a {int(info.width)} X {int(info.height)} map @ "
            f"{float(info.resolution):.3f} m/pix"
        )
        self._report(f"Writing map occupancy data to {prefix}.{self.image_format}")
        try:
            saved = save_occupancy_grid(
                prefix,
                msg,
                threshold_occupied=self.threshold_occupied,
                threshold_free=self.threshold_free,
                image_format=self.image_format,
            )
        except MapError as err:
            self.error = err
            if self._logged:  # a caller with its own report shows the error itself
                self.get_logger().error(str(err))
        else:
            self._report(f"Writing map occupancy data to {prefix}.yaml")
            self.saved_paths = (saved.image_path, saved.yaml_path)
            self.done = True
            self._report("Done")
        # map_saver's process exits once it has written the map (or failed to)
        self.exit_code = 0 if self.done else 1
        self.destroy_node()
