"""Small charts for run reports, drawn with Pillow (no plotting library needed)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

from PIL import Image, ImageDraw, ImageFont

__all__ = ["write_line_chart"]

_W, _H = 640, 400
_LEFT, _RIGHT, _TOP, _BOTTOM = 64, 20, 36, 48


def _ticks(lo: float, hi: float, n: int = 5) -> list[float]:
    """Round tick values covering ``lo..hi``."""
    span = hi - lo if hi > lo else 1.0
    raw = span / n
    mag = 10 ** math.floor(math.log10(raw))
    step = min((m * mag for m in (1, 2, 5, 10) if m * mag >= raw), default=raw)
    first = math.ceil(lo / step) * step
    return [first + k * step for k in range(int((hi - first) / step + 1e-9) + 1)]


def write_line_chart(
    path: Path,
    series: Sequence[tuple[Sequence[float], Sequence[float], tuple[int, int, int], str]],
    *,
    title: str,
    xlabel: str,
    ylabel: str,
    y_range: tuple[float, float] | None = None,
    hline: tuple[float, str] | None = None,
    markers: bool = False,
) -> None:
    """Draw ``(xs, ys, colour, label)`` series as lines on one chart and write it to
    ``path`` as PNG (temporary file, then rename). ``hline``: a dashed reference line
    ``(y, label)``; ``markers``: a dot on every point and whole-number x ticks (one point
    per episode, say)."""
    font = ImageFont.load_default()
    img = Image.new("RGB", (_W, _H), "white")
    draw = ImageDraw.Draw(img)
    xs_all = [float(x) for xs, _, _, _ in series for x in xs]
    ys_all = [float(y) for _, ys, _, _ in series for y in ys]
    x0, x1 = (min(xs_all), max(xs_all)) if xs_all else (0.0, 1.0)
    if x1 <= x0:
        x1 = x0 + 1.0
    if y_range is not None:
        y0, y1 = y_range
    else:
        y0, y1 = (min(ys_all), max(ys_all)) if ys_all else (0.0, 1.0)
        if y1 <= y0:
            y1 = y0 + 1.0
    pw, ph = _W - _LEFT - _RIGHT, _H - _TOP - _BOTTOM

    def px(x: float, y: float) -> tuple[float, float]:
        return _LEFT + (x - x0) / (x1 - x0) * pw, _TOP + (1.0 - (y - y0) / (y1 - y0)) * ph

    draw.rectangle([_LEFT, _TOP, _LEFT + pw, _TOP + ph], outline=(0, 0, 0))
    for t in _ticks(x0, x1):
        if markers and t != int(t):
            continue
        u, _ = px(t, y0)
        draw.line([(u, _TOP + ph), (u, _TOP + ph + 4)], fill=(0, 0, 0))
        draw.line([(u, _TOP), (u, _TOP + ph)], fill=(230, 230, 230))
        draw.text((u, _TOP + ph + 6), f"{t:g}", fill=(0, 0, 0), font=font, anchor="ma")
    for t in _ticks(y0, y1):
        _, v = px(x0, t)
        draw.line([(_LEFT - 4, v), (_LEFT, v)], fill=(0, 0, 0))
        draw.line([(_LEFT, v), (_LEFT + pw, v)], fill=(230, 230, 230))
        draw.text((_LEFT - 6, v), f"{t:g}", fill=(0, 0, 0), font=font, anchor="rm")
    if hline is not None:
        _, v = px(x0, hline[0])
        for u in range(_LEFT, _LEFT + pw, 8):
            draw.line([(u, v), (min(u + 4, _LEFT + pw), v)], fill=(120, 120, 120))
        draw.text((_LEFT + pw - 4, v - 2), hline[1], fill=(90, 90, 90), font=font, anchor="rd")
    for k, (xs, ys, colour, label) in enumerate(series):
        pts = [px(float(x), float(y)) for x, y in zip(xs, ys, strict=True)]
        if len(pts) > 1:
            draw.line(pts, fill=colour, width=1 if markers else 2)
        if markers or len(pts) == 1:
            for u, v in pts:
                draw.ellipse([u - 3, v - 3, u + 3, v + 3], fill=colour)
        draw.text((_LEFT + 8, _TOP + ph - 16 - 12 * k), label, fill=colour, font=font)
    draw.text((_W / 2, 10), title, fill=(0, 0, 0), font=font, anchor="ma")
    draw.text((_LEFT + pw / 2, _H - 16), xlabel, fill=(0, 0, 0), font=font, anchor="ma")
    draw.text((6, _TOP - 16), ylabel, fill=(0, 0, 0), font=font)
    tmp = path.with_name(path.name + ".part")
    img.save(tmp, format="PNG")
    tmp.replace(path)
