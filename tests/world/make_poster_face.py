"""Regenerate the face poster texture of the bundled office world.

The checked-in ``src/roverlab/world/bundled/models/poster_face/materials/textures/face.png`` is
the face of ``skimage.data.astronaut()`` (Eileen Collins, a NASA photograph in the public
domain) cropped to 200 x 200 pixels. Run this script to rebuild it::

    python tests/world/make_poster_face.py [OUT.png] [--astronaut astronaut.png]

It takes the photograph from scikit-image when installed (or from ``--astronaut``, the
``skimage/data/astronaut.png`` file of a scikit-image wheel); without either it draws a
simple shaded face with Pillow instead, so the world still has a face to look at.
Not a test: pytest does not collect it.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw, ImageFilter

DEFAULT_OUT = (
    Path(__file__).resolve().parents[2]
    / "src/roverlab/world/bundled/models/poster_face/materials/textures/face.png"
)
CROP = (120, 0, 320, 200)  # left, top, right, bottom in the 512 x 512 astronaut image


def astronaut_face(source: Path | None) -> Image.Image | None:
    """The cropped astronaut face, or None when the photograph is not available."""
    if source is not None:
        with Image.open(source) as im:
            return im.convert("RGB").crop(CROP)
    try:
        from skimage import data  # optional: not a roverlab dependency
    except ImportError:
        return None
    return Image.fromarray(np.asarray(data.astronaut(), dtype=np.uint8)).crop(CROP)


def drawn_face(size: int = 200) -> Image.Image:
    """A frontal face drawn with Pillow (fallback when the photograph is unavailable)."""
    im = Image.new("RGB", (size, size), (205, 200, 195))
    d = ImageDraw.Draw(im)
    s = size / 200.0

    def box(x0: float, y0: float, x1: float, y1: float) -> tuple[float, float, float, float]:
        return (x0 * s, y0 * s, x1 * s, y1 * s)

    d.ellipse(box(40, 10, 160, 120), fill=(120, 80, 40))  # hair
    d.ellipse(box(52, 35, 148, 170), fill=(224, 178, 148))  # face
    d.rectangle(box(82, 160, 118, 200), fill=(214, 168, 138))  # neck
    for cx in (78, 122):
        d.ellipse(box(cx - 14, 80, cx + 14, 94), fill=(250, 250, 250))  # eye whites
        d.ellipse(box(cx - 6, 81, cx + 6, 93), fill=(70, 50, 35))  # irises
        d.line(box(cx - 16, 72, cx + 16, 70), fill=(90, 60, 30), width=max(1, int(4 * s)))
    d.polygon([(100 * s, 92 * s), (92 * s, 122 * s), (108 * s, 122 * s)], fill=(205, 150, 120))
    d.chord(box(80, 128, 120, 150), 0, 180, fill=(170, 70, 70))  # mouth
    return im.filter(ImageFilter.GaussianBlur(1.2 * s))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", type=Path, default=DEFAULT_OUT)
    parser.add_argument("--astronaut", type=Path, help="skimage/data/astronaut.png")
    args = parser.parse_args()
    face = astronaut_face(args.astronaut) or drawn_face()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    face.save(args.out, optimize=True)
    print(f"wrote {args.out} ({face.size[0]} x {face.size[1]})")


if __name__ == "__main__":
    main()
