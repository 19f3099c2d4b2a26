"""image_transport's ``compressed`` transport: the codec (format strings and parameters as
compressed_image_transport), ``republish`` both ways and refusing theora, and the
simulator's camera offering ``<topic>/compressed`` only while someone subscribes."""

from __future__ import annotations

import io
from typing import Any

import numpy as np
import pytest
from PIL import Image

from roverlab.core import Context
from roverlab.description import load_robot
from roverlab.launch import build_launch, load_launch
from roverlab.launch.xml import LaunchError
from roverlab.msgs import array_to_image, image_to_array
from roverlab.msgs import classes as mc
from roverlab.perception.image_transport import (
    CompressedParams,
    ImageTransportError,
    compress,
    decompress,
)
from roverlab.perception.image_transport.node import Republish
from roverlab.sim.app import Simulation
from tests.description.conftest import robot


def _picture() -> np.ndarray[Any, Any]:
    img = np.zeros((48, 64, 3), np.uint8)
    img[:, :32] = (250, 10, 10)  # red left half, blue right half
    img[:, 32:] = (10, 10, 250)
    return img


def test_jpeg_and_png_as_compressed_image_transport() -> None:
    img = _picture()
    fmt, data = compress(img, "rgb8", CompressedParams())
    assert fmt == "rgb8; jpeg compressed bgr8" and data[:2] == b"\xff\xd8"
    back, encoding = decompress(fmt, data)
    away = np.r_[0:24, 40:64]  # JPEG blurs colour over the red/blue edge
    assert encoding == "rgb8" and np.abs(back.astype(int) - img)[:, away].max() < 20
    # bgr8 in: the JPEG holds the true colours, decoded back in bgr order
    fmt, data = compress(img[..., ::-1], "bgr8", CompressedParams())
    assert np.asarray(Image.open(io.BytesIO(data)))[10, 5, 0] > 200  # red stays red
    assert decompress(fmt, data)[1] == "bgr8"
    # png is lossless; mono16 stays 16-bit
    fmt, data = compress(img, "rgb8", CompressedParams(format="png", png_level=1))
    assert fmt == "rgb8; png compressed bgr8"
    assert np.array_equal(decompress(fmt, data)[0], img)
    depth = np.arange(48 * 64, dtype=np.uint16).reshape(48, 64) * 13
    fmt, data = compress(depth, "mono16", CompressedParams(format="png"))
    assert fmt == "mono16; png compressed mono16"
    back, encoding = decompress(fmt, data)
    assert encoding == "mono16" and np.array_equal(back, depth)
    # jpeg_quality is honoured: a lower quality makes a smaller file
    noisy = np.random.default_rng(0).integers(0, 255, (48, 64, 3), dtype=np.uint8)
    small = compress(noisy, "rgb8", CompressedParams(jpeg_quality=10))[1]
    assert len(small) < len(compress(noisy, "rgb8", CompressedParams(jpeg_quality=95))[1])


def test_bad_parameters_and_images_are_one_clear_error() -> None:
    with pytest.raises(ImageTransportError, match="format must be jpeg or png, got 'tiff'"):
        CompressedParams(format="tiff")
    with pytest.raises(ImageTransportError, match=r"jpeg_quality must be 1\.\.100, got 0"):
        CompressedParams(jpeg_quality=0)
    with pytest.raises(ImageTransportError, match=r"JPEG compression needs .* not 32FC1"):
        compress(np.zeros((4, 4), np.float32), "32FC1", CompressedParams())
    with pytest.raises(ImageTransportError, match="cannot decode"):
        decompress("jpeg", b"not an image")


def test_republish_raw_to_compressed_and_back_and_theora_refused() -> None:
    ctx = Context()
    Republish(ctx, in_transport="raw", node_name="squeeze",
              remappings={"in": "/cam/image_raw", "out": "/cam/small"},
              parameter_overrides={"format": "png"})  # fmt: skip
    Republish(ctx, in_transport="compressed", out_transport="raw", node_name="unsqueeze",
              remappings={"in": "/cam/small", "out": "/cam/again"})  # fmt: skip
    node = ctx.create_node("camera")
    pub = node.create_publisher(mc.Image, "/cam/image_raw", 1)
    packed: list[Any] = []
    again: list[Any] = []
    node.create_subscription(mc.CompressedImage, "/cam/small/compressed", packed.append, 5)
    node.create_subscription(mc.Image, "/cam/again", again.append, 5)
    ctx.spin_for(0.05)
    pub.publish(array_to_image(_picture(), "rgb8", frame_id="cam"))
    ctx.spin_for(0.1)
    assert [m.format for m in packed] == ["rgb8; png compressed bgr8"]
    assert len(again) == 1 and again[0].header.frame_id == "cam"
    assert np.array_equal(image_to_array(again[0]), _picture())
    with pytest.raises(ImageTransportError, match="'theora' is not provided"):
        Republish(ctx, in_transport="theora")
    ctx.shutdown()


def test_republish_in_a_launch_file_and_theora_is_one_line(tmp_path: Any) -> None:
    launch = tmp_path / "r.launch"
    launch.write_text(
        '<launch><node pkg="image_transport" type="republish" name="republish"'
        ' args="raw in:=/image_raw compressed out:=/image_small"/></launch>'
    )
    ctx = Context()
    build_launch(load_launch(launch), context=ctx)
    assert "/image_small/compressed" in ctx.graph.topics
    ctx.shutdown()
    launch.write_text(
        '<launch><node pkg="image_transport" type="republish" name="republish"'
        ' args="theora in:=/image_raw raw out:=/image_small"/></launch>'
    )
    with pytest.raises(LaunchError, match="image transport 'theora' is not provided") as err:
        build_launch(load_launch(launch), context=Context())
    assert "\n" not in str(err.value)


CAMERA = """
<link name="base_link"><collision><geometry><box size="0.3 0.2 0.1"/></geometry></collision>
</link><link name="cam"/>
<joint name="cam_joint" type="fixed"><parent link="base_link"/><child link="cam"/>
<origin xyz="0.1 0 0.2"/></joint>
<gazebo reference="cam">
  <sensor type="camera" name="cam">
    <update_rate>10</update_rate>
    <camera><horizontal_fov>1.2</horizontal_fov>
      <image><width>64</width><height>48</height></image></camera>
    <plugin name="cam_plugin" filename="libgazebo_ros_camera.so">
      <cameraName>/</cameraName><frameName>cam</frameName>
      <imageTopicName>image_raw</imageTopicName>
    </plugin>
  </sensor>
</gazebo>
"""


def test_the_simulated_camera_offers_compressed_only_while_subscribed() -> None:
    ctx = Context()
    sim = Simulation(context=ctx, world="empty", robot=load_robot(robot(CAMERA)),
                     parameters={"image_raw.compressed.jpeg_quality": 50})  # fmt: skip
    assert "/image_raw/compressed" in ctx.graph.topics  # offered (listed), not yet made
    ctx.spin_for(0.5)
    assert ctx.graph.topics["/image_raw/compressed"].published == 0
    got: list[Any] = []
    node = ctx.create_node("viewer")
    sub = node.create_subscription(mc.CompressedImage, "/image_raw/compressed", got.append, 5)
    ctx.spin_for(0.35)
    assert got and got[-1].format == "rgb8; jpeg compressed bgr8"
    assert got[-1].header.frame_id == "cam"
    pixels, _ = decompress(got[-1].format, bytes(got[-1].data))
    assert pixels.shape == (48, 64, 3)
    # the raw image nobody reads is not published; unsubscribed, nothing more is compressed
    assert ctx.graph.topics["/image_raw"].published == 0
    node.destroy_subscription(sub)
    made = ctx.graph.topics["/image_raw/compressed"].published
    ctx.spin_for(0.35)
    assert ctx.graph.topics["/image_raw/compressed"].published == made
    assert sim is not None
    ctx.shutdown()
