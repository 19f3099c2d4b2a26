"""rviz's point colour transformers for the LaserScan and PointCloud2 displays.

Pure functions on arrays. rviz colours every point on the CPU; the dashboard sends a
palette of a few dozen colours and one bucket index per point (:func:`color_buckets`),
the page looks the colour up. The palette is the transformer's colour scale sampled at
evenly spaced values of the normalised channel, so a bucket's colour is the exact rviz
colour of its bucket's centre (:func:`transformer_rgb` gives the exact colour per point).

* ``FlatColor``: every point in the display's ``color``;
* ``Intensity``: a channel (``intensity``, also found as ``intensities``, or any field)
  between ``min_intensity`` and ``max_intensity`` (or the cloud's own minimum and
  maximum with ``autocompute_intensity_bounds``), on rviz's rainbow (minimum red,
  maximum magenta; ``invert_rainbow`` swaps them) or from ``min_color`` to ``max_color``
  (``use_rainbow`` false);
* ``AxisColor``: a coordinate (``axis`` X, Y or Z, in the fixed frame with
  ``use_fixed_frame``) between ``min_value`` and ``max_value`` (or autocomputed), on the
  rainbow (lowest red, highest magenta).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, Final

import numpy as np
from numpy.typing import NDArray

from roverlab.viz.kinds import POINT_COLOR_OPTIONS

__all__ = [
    "BUCKETS",
    "channel_bounds",
    "color_buckets",
    "rviz_rainbow",
    "scale_rgb",
    "transformer_rgb",
]

BUCKETS: Final = 64
_NO_RANGE_INTENSITY: Final = 1e20  # rviz: equal bounds colour every point as the minimum
_NO_RANGE_AXIS: Final = 0.001

Option = Callable[[str], Any]


def rviz_rainbow(value: NDArray[Any]) -> NDArray[np.float64]:
    """rviz's ``getRainbowColor``: the HSV hue circle from 0 (magenta) through blue, cyan,
    green and yellow to 1 (red), ``value`` clipped to 0..1. Returns ``(N, 3)`` RGB 0..1."""
    v = np.clip(np.asarray(value, dtype=np.float64).reshape(-1), 0.0, 1.0)
    h = v * 5.0 + 1.0
    i = np.floor(h)
    f = h - i
    f = np.where(i % 2 == 0, 1.0 - f, f)
    n = 1.0 - f
    one, zero = np.ones_like(v), np.zeros_like(v)
    r = np.select([i <= 1, i == 2, i == 3, i == 4], [n, zero, zero, n], one)
    g = np.select([i <= 1, i == 2, i == 3, i == 4], [zero, n, one, one], n)
    b = np.select([i <= 1, i == 2, i == 3, i == 4], [one, one, n, zero], zero)
    return np.column_stack((r, g, b))


def channel_bounds(
    values: NDArray[Any], autocompute: bool, low: float, high: float
) -> tuple[float, float]:
    """The ``(min, max)`` a transformer scales between: the finite values' own minimum and
    maximum with ``autocompute`` (0, 0 when there are none), else ``low``, ``high``."""
    if not autocompute:
        return float(low), float(high)
    v = np.asarray(values, dtype=np.float64)
    finite = v[np.isfinite(v)]
    if finite.size == 0:
        return 0.0, 0.0
    return float(finite.min()), float(finite.max())


def _normalised(values: NDArray[Any], bounds: tuple[float, float], empty: float) -> NDArray[Any]:
    lo, hi = bounds
    span = hi - lo if hi != lo else empty
    v = np.asarray(values, dtype=np.float64).reshape(-1)
    return np.clip(np.where(np.isfinite(v), (v - lo) / span, 0.0), 0.0, 1.0)


def scale_rgb(transformer: str, t: NDArray[Any], option: Option) -> NDArray[np.float64]:
    """The colour (``(N, 3)``, 0..1) of normalised channel values ``t`` (0 at the
    minimum, 1 at the maximum) on ``transformer``'s scale (``Intensity`` or
    ``AxisColor``); ``option`` reads the display's options."""
    t = np.asarray(t, dtype=np.float64).reshape(-1)
    if transformer == "Intensity" and not bool(option("use_rainbow")):
        lo = np.asarray(option("min_color"), dtype=np.float64) / 255.0
        hi = np.asarray(option("max_color"), dtype=np.float64) / 255.0
        return t[:, None] * hi + (1.0 - t[:, None]) * lo
    if transformer == "Intensity" and bool(option("invert_rainbow")):
        return rviz_rainbow(t)
    return rviz_rainbow(1.0 - t)


def _t_and_bounds(
    transformer: str, values: NDArray[Any], option: Option
) -> tuple[NDArray[Any], tuple[float, float]]:
    if transformer == "Intensity":
        bounds = channel_bounds(
            values,
            bool(option("autocompute_intensity_bounds")),
            float(option("min_intensity")),
            float(option("max_intensity")),
        )
        return _normalised(values, bounds, _NO_RANGE_INTENSITY), bounds
    bounds = channel_bounds(
        values,
        bool(option("autocompute_value_bounds")),
        float(option("min_value")),
        float(option("max_value")),
    )
    return _normalised(values, bounds, _NO_RANGE_AXIS), bounds


def transformer_rgb(
    transformer: str, values: NDArray[Any], option: Option
) -> tuple[NDArray[np.float64], tuple[float, float]]:
    """The exact rviz colour of every point (``(N, 3)``, 0..1) and the bounds used, for
    the ``Intensity`` or ``AxisColor`` transformer over the channel ``values``."""
    t, bounds = _t_and_bounds(transformer, values, option)
    return scale_rgb(transformer, t, option), bounds


def color_buckets(
    transformer: str,
    *,
    count: int,
    flat_rgb: Sequence[int],
    alpha: float,
    values: NDArray[Any] | None = None,
    option: Option | None = None,
    buckets: int = BUCKETS,
) -> tuple[NDArray[np.int64] | None, NDArray[np.uint8], tuple[float, float] | None]:
    """Bucket index per point, an RGBA palette (as :func:`~roverlab.viz.protocol.
    encode_points` wants) and the bounds the channel was scaled between.

    ``FlatColor`` (or no ``values``): one bucket of ``flat_rgb``, no bounds. ``Intensity``
    / ``AxisColor``: ``values`` (the channel, or the chosen coordinate) normalised as
    rviz does, in ``buckets`` steps; ``option`` reads the display's options (rviz's
    defaults when None: autocomputed bounds, the rainbow).
    """
    a = round(max(0.0, min(1.0, alpha)) * 255)
    if transformer not in ("Intensity", "AxisColor") or values is None or count == 0:
        return None, np.array([[*flat_rgb, a]], dtype=np.uint8), None
    read = option if option is not None else POINT_COLOR_OPTIONS.__getitem__
    t, bounds = _t_and_bounds(transformer, values, read)
    idx = np.rint(t * (buckets - 1)).astype(np.int64)
    rgb = scale_rgb(transformer, np.linspace(0.0, 1.0, buckets), read)
    palette = np.column_stack(
        ((rgb * 255.0 + 0.5).astype(np.uint8), np.full(buckets, a, dtype=np.uint8))
    )
    return idx, palette, bounds
