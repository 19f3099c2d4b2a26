"""rviz's point colour transformers (Intensity, AxisColor) as the dashboard computes them."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from roverlab.viz.colours import channel_bounds, color_buckets, rviz_rainbow, transformer_rgb
from roverlab.viz.kinds import POINT_COLOR_OPTIONS
from roverlab.viz.protocol import rainbow


def _options(**over: Any) -> Any:
    opts = {**POINT_COLOR_OPTIONS, **over}
    return opts.__getitem__


def _rviz_rainbow_reference(value: float) -> tuple[float, float, float]:
    """rviz's getRainbowColor, transcribed branch by branch (one value)."""
    value = min(max(value, 0.0), 1.0)
    h = value * 5.0 + 1.0
    i = int(np.floor(h))
    f = h - i
    if i % 2 == 0:
        f = 1.0 - f
    n = 1.0 - f
    if i <= 1:
        return n, 0.0, 1.0
    if i == 2:
        return 0.0, n, 1.0
    if i == 3:
        return 0.0, 1.0, n
    if i == 4:
        return n, 1.0, 0.0
    return 1.0, n, 0.0


def test_rainbow_matches_rviz_everywhere() -> None:
    v = np.linspace(-0.2, 1.2, 141)
    ref = np.array([_rviz_rainbow_reference(float(x)) for x in v])
    assert np.allclose(rviz_rainbow(v), ref)
    assert np.allclose(rainbow(v), ref)  # the image colour map's rainbow is the same scale
    assert rviz_rainbow(np.array([0.0, 1.0])).tolist() == [[1, 0, 1], [1, 0, 0]]


def test_intensity_rainbow_autocomputed_low_red_high_magenta() -> None:
    inten = np.array([10.0, 20.0, 30.0, 110.0])
    rgb, bounds = transformer_rgb("Intensity", inten, _options())
    assert bounds == (10.0, 110.0)
    assert rgb[0].tolist() == [1.0, 0.0, 0.0]  # the minimum: red
    assert rgb[-1].tolist() == [1.0, 0.0, 1.0]  # the maximum: magenta
    # in between: rviz's value = 1 - (v - min) / (max - min) on the rainbow
    assert np.allclose(rgb[1], _rviz_rainbow_reference(1.0 - 0.1))
    inverted, _ = transformer_rgb("Intensity", inten, _options(invert_rainbow=True))
    assert inverted[0].tolist() == [1.0, 0.0, 1.0] and inverted[-1].tolist() == [1.0, 0.0, 0.0]


def test_intensity_fixed_bounds_clip_and_min_max_colours() -> None:
    inten = np.array([-5.0, 0.0, 50.0, 100.0, 400.0])
    opts = _options(autocompute_intensity_bounds=False, min_intensity=0.0, max_intensity=100.0,
                    use_rainbow=False, min_color=[0, 0, 255], max_color=[255, 255, 0])  # fmt: skip
    rgb, bounds = transformer_rgb("Intensity", inten, opts)
    assert bounds == (0.0, 100.0)
    assert rgb[0].tolist() == [0.0, 0.0, 1.0] and rgb[1].tolist() == [0.0, 0.0, 1.0]  # clipped
    assert np.allclose(rgb[2], [0.5, 0.5, 0.5])  # half way from blue to yellow
    assert rgb[3].tolist() == [1.0, 1.0, 0.0] and rgb[4].tolist() == [1.0, 1.0, 0.0]


def test_equal_bounds_colour_everything_as_the_minimum() -> None:
    rgb, _ = transformer_rgb("Intensity", np.full(3, 7.0), _options())
    assert np.allclose(rgb, [[1.0, 0.0, 0.0]] * 3)  # rviz divides by 1e20: all red
    assert channel_bounds(np.array([np.nan, np.inf]), True, 0.0, 1.0) == (0.0, 0.0)


def test_buckets_sample_the_exact_scale() -> None:
    rng = np.random.default_rng(7)
    inten = rng.uniform(0.0, 1000.0, 500)
    for opts in (_options(), _options(use_rainbow=False, min_color=[10, 20, 30])):
        idx, pal, bounds = color_buckets("Intensity", count=500, flat_rgb=[0, 0, 0], alpha=0.5,
                                         values=inten, option=opts)  # fmt: skip
        assert idx is not None and bounds == (inten.min(), inten.max())
        exact, _ = transformer_rgb("Intensity", inten, opts)
        # a bucket's colour is the exact colour within half a bucket of the value
        err = np.abs(pal[idx, :3].astype(float) - exact * 255.0).max()
        assert err <= 255.0 * 5.0 / 63.0 / 2.0 + 1.0
        assert (pal[:, 3] == 128).all()


def test_axis_colour_fixed_bounds() -> None:
    z = np.array([-20.0, 0.0, 20.0])
    rgb, bounds = transformer_rgb("AxisColor", z, _options(autocompute_value_bounds=False))
    assert bounds == (-10.0, 10.0)
    assert rgb[0].tolist() == [1.0, 0.0, 0.0] and rgb[2].tolist() == [1.0, 0.0, 1.0]
    assert np.allclose(rgb[1], _rviz_rainbow_reference(0.5))


@pytest.mark.parametrize("transformer", ["FlatColor", "RGB8"])
def test_other_transformers_are_flat_here(transformer: str) -> None:
    idx, pal, bounds = color_buckets(transformer, count=3, flat_rgb=[9, 8, 7], alpha=1.0,
                                     values=np.arange(3.0))  # fmt: skip
    assert idx is None and bounds is None and pal.tolist() == [[9, 8, 7, 255]]
