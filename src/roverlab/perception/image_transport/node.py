"""image_transport's nodes: the ``compressed`` publisher a camera driver offers beside its
raw image, and ``image_transport/republish``.

* :class:`CompressedPublisher` (in :mod:`.publisher`, re-exported here):
  ``<topic>/compressed`` next to a raw ``<topic>``, compressed only while someone
  subscribes to it.
* :class:`Republish`: ``rosrun image_transport republish IN_TRANSPORT in:=IN
  [OUT_TRANSPORT] out:=OUT``: ``raw`` -> ``compressed`` reads ``in`` and publishes
  ``out/compressed`` (private ``format``, ``jpeg_quality``, ``png_level``), ``compressed``
  -> ``raw`` reads ``in/compressed`` and publishes ``out``; ``theora`` is refused.
"""

from __future__ import annotations

from typing import Any

from roverlab.core import Context, Node
from roverlab.msgs import array_to_image
from roverlab.msgs import classes as mc
from roverlab.perception.image_transport.codec import (
    ImageTransportError,
    check_transport,
    decompress,
)
from roverlab.perception.image_transport.publisher import (
    CompressedPublisher,
    compressed_message,
    compressed_params,
)

__all__ = ["CompressedPublisher", "Republish", "compressed_message"]


class Republish(Node):
    """``image_transport/republish``: one transport in, another out.

    Args:
        context: the context the node joins.
        in_transport: ``raw`` or ``compressed``.
        out_transport: ``raw`` or ``compressed`` (default: the other one).
        node_name: defaults to ``republish``.
        **node_kwargs: ``namespace``, ``parameter_overrides``, ``remappings`` (``in``
            and ``out`` are the base topics).

    Raises:
        ImageTransportError: a transport other than raw/compressed (theora), the same
            transport in and out, or a bad format parameter.
    """

    def __init__(
        self,
        context: Context,
        *,
        in_transport: str = "raw",
        out_transport: str | None = None,
        node_name: str = "republish",
        **node_kwargs: Any,
    ) -> None:
        check_transport(in_transport)
        out = out_transport or ("compressed" if in_transport == "raw" else "raw")
        check_transport(out)
        if out == in_transport:
            raise ImageTransportError(f"republish {in_transport} to {out}: nothing to convert")
        super().__init__(node_name, context=context, **node_kwargs)
        self.params = compressed_params(self, "")
        self.republished = 0
        self._last_error = ""
        # the base topics are resolved (remapped) first, the transport's suffix added after
        base_in, base_out = self.resolve_topic_name("in"), self.resolve_topic_name("out")
        if in_transport == "raw":
            self._out = self.create_publisher(mc.CompressedImage, f"{base_out}/compressed", 1)
            self.create_subscription(mc.Image, base_in, self._on_raw, 1)
        else:
            self._out = self.create_publisher(mc.Image, base_out, 1)
            self.create_subscription(
                mc.CompressedImage, f"{base_in}/compressed", self._on_compressed, 1
            )

    def _on_raw(self, image: Any) -> None:
        try:
            self._out.publish(compressed_message(image, self.params))
            self.republished += 1
        except ImageTransportError as err:
            self._report(str(err))

    def _on_compressed(self, msg: Any) -> None:
        try:
            pixels, encoding = decompress(str(msg.format), bytes(memoryview(msg.data)))
        except ImageTransportError as err:
            self._report(str(err))
            return
        image = array_to_image(pixels, encoding, frame_id=str(msg.header.frame_id))
        image.header = msg.header
        self._out.publish(image)
        self.republished += 1

    def _report(self, text: str) -> None:
        """Log an error once, not once per image."""
        if text != self._last_error:
            self._last_error = text
            self.get_logger().error(text)
