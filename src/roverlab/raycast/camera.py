"""2.5-D pinhole camera: RGB and depth images of a Scene, and depth back-projection.

:func:`render` casts planar rays through the scene's grid, one per image column for a level
camera, and keeps the :data:`MAX_LAYERS` nearest surfaces along each (stopping at the first
that covers the whole vertical field of view). Each pixel then takes them from near to far:
the first whose ``[zmin, zmax]`` holds the height of the pixel's ray at that distance is
what the pixel sees (a cylinder's top or bottom cap is seen between its entry and exit
distances); a ray that reaches the ground (z = 0) first sees the floor (1 m checker tiles);
a ray that meets nothing within ``far`` sees the sky. Walls are faces without thickness: a
box seen from above its top shows its inner faces, not a lid.

Camera model: square pixels, principal point at the image centre,
``fx = fy = (width / 2) / tan(hfov / 2)``, ``cx = (width - 1) / 2``,
``cy = (height - 1) / 2`` (pixel ``(u, v)`` has its centre at ``(u, v)``), so the pixel
ray in the camera body frame (x forward, y left, z up) is ``(1, (cx - u)/fx, (cy - v)/fy)``.
``pitch > 0`` tilts the camera down (a positive rotation about the body y axis, REP 103).
With ``pitch = 0`` the projection is an exact pinhole and each surface covers a span of
rows of its column (the fast path). With a pitch the pixels of a column look along
different azimuths: surfaces are gathered along azimuths spaced at most one column apart
and each pixel uses the one nearest its own ray, so the image is the tilted pinhole's to
within half a column (straight edges stay straight); this path costs 2-3 times more.

Depth is the z-depth along the optical axis (as a depth camera reports it), ``nan`` for
sky, beyond ``far`` or nearer than ``near`` (such pixels keep their colour). Colours are
flat-shaded by a fixed light and a mild distance falloff: the same inputs give the same
image, bit for bit. Noise is left to the caller.

Frames: :func:`depth_to_points` returns points in the camera's optical frame (x right,
y down, z forward, REP 103 ``_optical``); :func:`optical_to_body` and
:func:`body_to_optical` convert to and from the body frame (x forward, y left, z up).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.raycast.accel import scene_grid
from roverlab.raycast.camera_fill import fill_pitched
from roverlab.raycast.camera_hits import MAX_LAYERS, collect_hits
from roverlab.raycast.camera_level import fill_level
from roverlab.raycast.errors import RaycastInputError
from roverlab.raycast.scene import Scene

__all__ = [
    "MAX_LAYERS",
    "CameraIntrinsics",
    "body_to_optical",
    "camera_intrinsics",
    "depth_to_points",
    "optical_to_body",
    "render",
    "render_rgb",
]

_jit = numba.njit(cache=True, nogil=True)

_TEX_CACHE_ATTR = "_raycast_textures"


@dataclass(frozen=True)
class CameraIntrinsics:
    """Pinhole intrinsics of a :func:`render` image (``sensor_msgs/CameraInfo`` K)."""

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float

    @property
    def k(self) -> NDArray[np.float64]:
        """The 3x3 camera matrix ``[[fx, 0, cx], [0, fy, cy], [0, 0, 1]]``."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    @property
    def vfov(self) -> float:
        """Vertical field of view (rad) between the outer pixel edges."""
        return 2.0 * math.atan(0.5 * self.height / self.fy)


def camera_intrinsics(width: int, height: int, hfov: float) -> CameraIntrinsics:
    """Intrinsics of a ``width`` x ``height`` image with horizontal field of view ``hfov``.

    Raises:
        RaycastInputError: non-positive size, ``hfov`` outside (0, pi).
    """
    w = int(width)
    h = int(height)
    fov = float(hfov)
    if w <= 0 or h <= 0:
        raise RaycastInputError(f"image size must be positive, got {width}x{height}")
    if not 0.0 < fov < math.pi:
        raise RaycastInputError(f"hfov must be in (0, pi) rad, got {hfov}")
    f = 0.5 * w / math.tan(0.5 * fov)
    return CameraIntrinsics(width=w, height=h, fx=f, fy=f, cx=0.5 * (w - 1), cy=0.5 * (h - 1))


@_jit
def _render_kernel(
    x: float,
    y: float,
    z: float,
    yaw: float,
    pitch: float,
    fx: float,
    fy: float,
    cx: float,
    cy: float,
    near: float,
    far: float,
    segs: NDArray[np.float64],
    segz: NDArray[np.float64],
    segrgb: NDArray[np.uint8],
    segtex: NDArray[np.int32],
    circs: NDArray[np.float64],
    circz: NDArray[np.float64],
    circrgb: NDArray[np.uint8],
    tex_data: NDArray[np.uint8],
    tex_off: NDArray[np.int64],
    tex_shape: NDArray[np.int64],
    floor_rgb: NDArray[np.uint8],
    sky_rgb: NDArray[np.uint8],
    gx0: float,
    gy0: float,
    cell: float,
    nx: int,
    ny: int,
    cstart: NDArray[np.int32],
    items: NDArray[np.int32],
    nseg: int,
    rgb: NDArray[np.uint8],
    depth: NDArray[np.float32],
    with_depth: bool,
) -> None:
    width = rgb.shape[1]
    ct = math.cos(pitch)
    st = math.sin(pitch)
    # image rows in the camera's vertical plane: direction (hx, 0, vz) per unit depth
    b_top = cy / fy
    b_bot = -cy / fy
    hx_top = ct + b_top * st
    hx_bot = ct + b_bot * st
    hx_min = min(hx_top, hx_bot)
    hx_max = max(hx_top, hx_bot)
    el_top = (-st + b_top * ct) / hx_top  # tangent of the top row's elevation
    el_bot = (-st + b_bot * ct) / hx_bot
    # Azimuth samples, uniform in q = tan(azimuth - yaw), q_k = q0 - k * dq. Level camera:
    # one per column. Tilted: the pixels of a column look along different azimuths; sample
    # so that every pixel is within half a column of a sample and take the nearest.
    if pitch == 0.0:
        n_az = width
        q0 = cx / fx
        dq = 1.0 / fx
    else:
        q0 = (cx / fx) / hx_min
        n_az = min(int(math.ceil(2.0 * q0 * fx * hx_max - 1e-6)) + 1, 8 * width)
        if (n_az - width) % 2 != 0:
            n_az += 1  # same parity as the width: an odd image keeps its centre sample
        dq = 2.0 * q0 / max(n_az - 1, 1)
    az_dx, az_dy, n_hits, h_in, h_out, h_id, h_u, h_shade, h_rgb = collect_hits(
        x, y, z, yaw, n_az, q0, dq, el_top, el_bot, hx_max, far,
        segs, segz, circs, circz, gx0, gy0, cell, nx, ny, cstart, items, nseg,
        segrgb, circrgb,
    )  # fmt: skip
    if pitch == 0.0:
        fill_level(
            x, y, z, yaw, fx, fy, cx, cy, near, far,
            segz, segtex, circz, tex_data, tex_off, tex_shape,
            floor_rgb, sky_rgb, nseg,
            n_hits, h_in, h_out, h_id, h_u, h_shade, h_rgb, rgb, depth, with_depth,
        )  # fmt: skip
    else:
        fill_pitched(
            x, y, z, pitch, fx, fy, cx, cy, near, far, q0, dq,
            segz, segtex, circz, tex_data, tex_off, tex_shape,
            floor_rgb, sky_rgb, nseg,
            az_dx, az_dy, n_hits, h_in, h_out, h_id, h_u, h_shade, h_rgb, rgb, depth,
        )  # fmt: skip


def _packed_textures(
    scene: Scene,
) -> tuple[NDArray[np.uint8], NDArray[np.int64], NDArray[np.int64]]:
    """All textures as one (T, 3) texel array, per-texture offsets and (h, w); cached."""
    cached = scene.__dict__.get(_TEX_CACHE_ATTR)
    if cached is not None and cached[0] is scene.textures and cached[1] == len(scene.textures):
        return cached[2]
    chunks: list[NDArray[np.uint8]] = []
    offsets: list[int] = []
    shapes: list[tuple[int, int]] = []
    total = 0
    for i, tex in enumerate(scene.textures):
        img = np.asarray(tex)
        if img.ndim == 2:
            img = np.repeat(img[:, :, None], 3, axis=2)
        if img.ndim != 3 or img.shape[2] not in (3, 4) or img.shape[0] == 0 or img.shape[1] == 0:
            raise RaycastInputError(f"texture {i} must be an (H, W, 3) image, got {img.shape}")
        img = np.ascontiguousarray(img[:, :, :3], dtype=np.uint8)
        chunks.append(img.reshape(-1, 3))
        offsets.append(total)
        shapes.append((img.shape[0], img.shape[1]))
        total += img.shape[0] * img.shape[1]
    data = np.concatenate(chunks) if chunks else np.zeros((1, 3), dtype=np.uint8)
    off = np.array(offsets if offsets else [0], dtype=np.int64)
    shp = np.array(shapes if shapes else [(1, 1)], dtype=np.int64).reshape(-1, 2)
    packed = (np.ascontiguousarray(data), off, shp)
    scene.__dict__[_TEX_CACHE_ATTR] = (scene.textures, len(scene.textures), packed)
    return packed


def _rgb3(name: str, value: object) -> NDArray[np.uint8]:
    arr = np.asarray(value, dtype=np.int64).reshape(-1)
    if arr.shape[0] != 3 or arr.min() < 0 or arr.max() > 255:
        raise RaycastInputError(f"{name} must be three values in 0..255, got {value}")
    return arr.astype(np.uint8)


def render(
    scene: Scene,
    x: float,
    y: float,
    z: float,
    yaw: float,
    *,
    hfov: float,
    width: int,
    height: int,
    near: float,
    far: float,
    pitch: float = 0.0,
) -> tuple[NDArray[np.uint8], NDArray[np.float32]]:
    """Render the RGB and depth images seen by a pinhole camera (see the module docstring).

    Args:
        scene: the scene (its grid and packed textures are cached on it).
        x, y, z: camera centre in the world frame (m).
        yaw: heading of the optical axis (rad, world frame).
        hfov: horizontal field of view (rad), in (0, pi).
        width, height: image size (pixels).
        near, far: clip distances (m) along the optical axis, ``0 <= near < far``.
        pitch: downward tilt (rad); ``|pitch| + vfov / 2`` must stay below pi/2.

    Returns:
        ``(rgb, depth)``: (H, W, 3) uint8 image and (H, W) float32 z-depth in metres
        (``nan`` for sky, beyond ``far`` or nearer than ``near``).

    Raises:
        RaycastInputError: non-finite pose, bad size, field of view, clip range or pitch.
    """
    intr = camera_intrinsics(width, height, hfov)
    depth = np.empty((intr.height, intr.width), dtype=np.float32)
    rgb = _render(scene, (x, y, z, yaw, pitch), intr, near, far, None, depth)
    return rgb, depth


def render_rgb(
    scene: Scene,
    x: float,
    y: float,
    z: float,
    yaw: float,
    *,
    hfov: float,
    width: int,
    height: int,
    near: float,
    far: float,
    pitch: float = 0.0,
    out: NDArray[np.uint8] | None = None,
) -> NDArray[np.uint8]:
    """:func:`render`'s RGB image alone (a level camera then skips the depth image).

    Args:
        out: an (H, W, 3) C-contiguous uint8 array to render into (every pixel is
            written), or None for a new one.

    Raises:
        RaycastInputError: as :func:`render`; an ``out`` of another shape or type.
    """
    intr = camera_intrinsics(width, height, hfov)
    if out is not None and (
        out.shape != (intr.height, intr.width, 3)
        or out.dtype != np.uint8
        or not out.flags.c_contiguous
    ):
        raise RaycastInputError(
            f"out must be a C-contiguous ({intr.height}, {intr.width}, 3) uint8 array, "
            f"got {out.dtype} {out.shape}"
        )
    level = float(pitch) == 0.0
    depth = _NO_DEPTH if level else np.empty((intr.height, intr.width), dtype=np.float32)
    return _render(scene, (x, y, z, yaw, pitch), intr, near, far, out, depth)


_NO_DEPTH = np.zeros((1, 1), dtype=np.float32)


def _render(
    scene: Scene,
    pose: tuple[float, float, float, float, float],
    intr: CameraIntrinsics,
    near: float,
    far: float,
    out: NDArray[np.uint8] | None,
    depth: NDArray[np.float32],
) -> NDArray[np.uint8]:
    """Validate and render into ``out`` (or a new image); ``depth`` is filled unless it
    is ``_NO_DEPTH`` (a level camera only)."""
    vals = [float(v) for v in pose]
    if not all(math.isfinite(v) for v in vals):
        raise RaycastInputError(f"camera pose must be finite, got {vals}")
    x_, y_, z_, yaw_, pitch_ = vals
    near_ = float(near)
    far_ = float(far)
    if not (0.0 <= near_ < far_ and math.isfinite(far_)):
        raise RaycastInputError(f"need 0 <= near < far < inf, got near={near}, far={far}")
    if abs(pitch_) + 0.5 * intr.vfov >= 0.5 * math.pi:
        raise RaycastInputError(
            f"|pitch| + vfov/2 must be below pi/2, got pitch={pitch_}, vfov={intr.vfov}"
        )
    g = scene_grid(scene)
    tex_data, tex_off, tex_shape = _packed_textures(scene)
    rgb = np.empty((intr.height, intr.width, 3), dtype=np.uint8) if out is None else out
    _render_kernel(
        x_, y_, z_, yaw_, pitch_, intr.fx, intr.fy, intr.cx, intr.cy, near_, far_,
        scene.segments, scene.segment_z, scene.segment_rgb, scene.segment_texture,
        scene.circles, scene.circle_z, scene.circle_rgb,
        tex_data, tex_off, tex_shape,
        _rgb3("floor_rgb", scene.floor_rgb), _rgb3("sky_rgb", scene.sky_rgb),
        g.x0, g.y0, g.cell, g.nx, g.ny, g.cell_start, g.items, g.n_segments,
        rgb, depth, depth is not _NO_DEPTH,
    )  # fmt: skip
    return rgb


def depth_to_points(
    depth: ArrayLike, hfov: float, *, keep_invalid: bool = False
) -> NDArray[np.float32]:
    """Back-project a depth image into 3-D points in the camera's optical frame.

    Uses the intrinsics of :func:`camera_intrinsics` (those :func:`render` uses):
    ``X = (u - cx) * d / fx``, ``Y = (v - cy) * d / fy``, ``Z = d``.

    Args:
        depth: (H, W) z-depth image (m), ``nan``/``inf``/``<= 0`` for no return.
        hfov: horizontal field of view the image was rendered with (rad).
        keep_invalid: keep every pixel in row-major order (an organised cloud of
            ``H * W`` points, invalid ones all ``nan``) instead of dropping them.

    Returns:
        (N, 3) float32 points ``x right, y down, z forward``; row-major pixel order.

    Raises:
        RaycastInputError: ``depth`` not 2-D, bad ``hfov``.
    """
    d = np.asarray(depth, dtype=np.float32)
    if d.ndim != 2:
        raise RaycastInputError(f"depth must be an (H, W) image, got shape {d.shape}")
    intr = camera_intrinsics(d.shape[1], d.shape[0], hfov)
    xs = ((np.arange(intr.width) - intr.cx) / intr.fx).astype(np.float32)
    ys = ((np.arange(intr.height) - intr.cy) / intr.fy).astype(np.float32)
    valid = np.isfinite(d) & (d > 0)
    z = np.where(valid, d, np.float32(np.nan))
    grid = np.empty((d.shape[0], d.shape[1], 3), dtype=np.float32)
    grid[:, :, 0] = xs[None, :] * z
    grid[:, :, 1] = ys[:, None] * z
    grid[:, :, 2] = z
    pts = grid.reshape(-1, 3)
    if keep_invalid:
        return pts
    return np.ascontiguousarray(pts[valid.reshape(-1)])


def _points3(points: ArrayLike) -> NDArray[np.floating]:
    """``points`` as a float array of shape (..., 3) (float64 unless already floating)."""
    p = np.asarray(points)
    if not np.issubdtype(p.dtype, np.floating):
        p = p.astype(np.float64)
    if p.shape[-1] != 3:
        raise RaycastInputError(f"points must have shape (..., 3), got {p.shape}")
    return p


def optical_to_body(points: ArrayLike) -> NDArray[np.floating]:
    """Optical-frame points (x right, y down, z forward) -> body frame (x fwd, y left, z up).

    Args:
        points: (..., 3) array.

    Returns:
        Array of the same shape and float dtype: ``(z, -x, -y)``.
    """
    p = _points3(points)
    return np.stack([p[..., 2], -p[..., 0], -p[..., 1]], axis=-1)


def body_to_optical(points: ArrayLike) -> NDArray[np.floating]:
    """Body-frame points (x fwd, y left, z up) -> optical frame (x right, y down, z fwd).

    Args:
        points: (..., 3) array.

    Returns:
        Array of the same shape and float dtype: ``(-y, -z, x)``.
    """
    p = _points3(points)
    return np.stack([-p[..., 1], -p[..., 2], p[..., 0]], axis=-1)
