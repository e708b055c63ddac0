"""Scanning a colour-coded image: the pixels of each known colour, and the blobs of every other colour.

Buchsbaum & Blumberg 2005, §4.2: "By scanning the visual image for pixels of a particular color, the creature can
'see' an object ... by examining the screen-space coordinates of an object's centroid in the point-of-view rendering.
The (x,y) screen-space coordinates can then be combined with information from the rendering's depth-buffer."

:func:`scan` reads the drawn pixels of one rendered frame (those where the depth buffer holds something): each one's
flat colour packed into one integer (:func:`pack`), its row and column, and its depth in metres along the view axis.
Each colour is looked up among the *known* colours (the watched body's parts, as the observer knows them, and its
limbs); a known part's pixels, wherever they lie, give its pixel count, centroid and nearest depth. Every other colour
is an object's: each 8-connected blob of one colour (:func:`scipy.ndimage.label`) is one object seen, with its pixel
count, centroid, nearest depth and colour. A part's colour seen in two places (an object painted like the part) is
the part where the part was, and an object elsewhere. Two things of one colour that touch in the picture are one blob, as they
would be to an eye that knows things only by their colour. :func:`unproject` turns a centroid and a depth back into
a point in the eye's frame (a pinhole camera).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

__all__ = ["Scan", "pack", "scan", "unpack", "unproject"]

_EIGHT = np.ones((3, 3), dtype=bool)  # 8-connected blobs


def pack(rgb: np.ndarray) -> np.ndarray:
    """RGB (..., 3) in 0..255 as one integer per colour, ``r | g << 8 | b << 16``: what a pixel read as RGBA and viewed
    as a little-endian 32-bit integer holds in its lower three bytes."""
    rgb = np.rint(np.asarray(rgb, dtype=float)).astype(np.uint32)
    return rgb[..., 0] | (rgb[..., 1] << 8) | (rgb[..., 2] << 16)


def unpack(key: int) -> np.ndarray:
    """The RGB (3,) of a packed colour (:func:`pack`)."""
    return np.array([key & 255, (key >> 8) & 255, (key >> 16) & 255], dtype=float)


@dataclass
class Scan:
    """One frame scanned: per watched part (P,) pixel count, centroid column ``u`` and row ``v`` (from the top) and
    nearest depth (m; NaN where unseen); per object blob (B,) the same, and its colour (B, 3) RGB."""

    part_pixels: np.ndarray
    part_u: np.ndarray
    part_v: np.ndarray
    part_near: np.ndarray
    blob_pixels: np.ndarray
    blob_u: np.ndarray
    blob_v: np.ndarray
    blob_near: np.ndarray
    blob_colours: np.ndarray


def scan(keys: np.ndarray, rows: np.ndarray, cols: np.ndarray, depth: np.ndarray, known: dict[int, int],
         n_parts: int, min_pixels: int = 1, previous: np.ndarray | None = None) -> Scan:
    """Scan the drawn pixels of one frame (see the module): their packed colours ``keys`` (n,) (:func:`pack`), rows
    (from the top) and columns (n,), and depths (n,) in metres.

    ``known`` maps a packed colour to a part index in ``0..n_parts - 1``, or to -1 for a colour that is body but not
    tracked (limbs). Blobs under ``min_pixels`` pixels are left out. A part's colour spread far wider than one
    compact blob (something else of its colour in the picture: a ball painted the hand's red) is split into its
    blobs: the part is the one nearest where the part was found in the last frame (``previous``, (P, 2) columns and
    rows, NaN where unknown), else nearest the rest of the body; the others are objects of that colour.
    """
    values, which = np.unique(keys, return_inverse=True)  # the few colours in the picture
    part_of = np.array([known.get(int(c), -2) for c in values], dtype=np.int64)  # -2: an object's colour
    part = part_of[which]
    mine = part >= 0
    p = part[mine]
    count = np.bincount(p, minlength=n_parts).astype(float)
    with np.errstate(invalid="ignore", divide="ignore"):
        u = np.bincount(p, weights=cols[mine], minlength=n_parts) / count
        v = np.bincount(p, weights=rows[mine], minlength=n_parts) / count
    near = np.full(n_parts, np.inf)
    np.minimum.at(near, p, depth[mine])
    blobs = [_blobs(rows[which == k], cols[which == k], depth[which == k], int(values[k]), min_pixels)
             for k in np.flatnonzero(part_of == -2)]
    for k in _scattered(part_of, which, rows, cols, count):  # a part's colour in more than one place
        i = int(part_of[k])
        pieces = _blobs(rows[which == k], cols[which == k], depth[which == k], int(values[k]), 1)
        if len(pieces) < 2:
            continue
        others = (count > 0) & (np.arange(n_parts) != i)
        here = previous[i] if previous is not None and np.isfinite(previous[i]).all() else (
            np.array([np.average(u[others], weights=count[others]), np.average(v[others], weights=count[others])])
            if others.any() else pieces[np.argmax(pieces[:, 0]), 1:3])
        chosen = int(np.argmin(np.hypot(pieces[:, 1] - here[0], pieces[:, 2] - here[1])))
        count[i], u[i], v[i], near[i] = pieces[chosen, :4]
        rest = np.delete(pieces, chosen, axis=0)
        blobs.append(rest[rest[:, 0] >= min_pixels])
    near[~np.isfinite(near)] = np.nan
    blob = np.concatenate(blobs, axis=0) if blobs else np.zeros((0, 7))
    return Scan(count, u, v, near, blob[:, 0], blob[:, 1], blob[:, 2], blob[:, 3], blob[:, 4:7])


def _scattered(part_of: np.ndarray, which: np.ndarray, rows: np.ndarray, cols: np.ndarray,
               count: np.ndarray) -> list[int]:
    """The colours (indices into the picture's colours) of parts whose pixels spread over more than a compact blob
    of their number could (a disc of n pixels is about 1.13 sqrt(n) across; 2.5 sqrt(n) + 4 is allowed)."""
    out = []
    for k in np.flatnonzero(part_of >= 0):
        at = which == k
        extent = max(int(np.ptp(rows[at])), int(np.ptp(cols[at]))) + 1
        if extent > 2.5 * np.sqrt(count[part_of[k]]) + 4:
            out.append(int(k))
    return out


def _blobs(rows: np.ndarray, cols: np.ndarray, depth: np.ndarray, key: int, min_pixels: int) -> np.ndarray:
    """The connected blobs of one colour's pixels: rows of (pixels, u, v, nearest depth, r, g, b)."""
    r0, c0 = rows.min(), cols.min()
    mask = np.zeros((rows.max() - r0 + 1, cols.max() - c0 + 1), dtype=bool)
    mask[rows - r0, cols - c0] = True
    labels, n = ndimage.label(mask, structure=_EIGHT)
    label = labels[rows - r0, cols - c0] - 1
    count = np.bincount(label, minlength=n).astype(float)
    u = np.bincount(label, weights=cols, minlength=n) / count
    v = np.bincount(label, weights=rows, minlength=n) / count
    near = np.full(n, np.inf)
    np.minimum.at(near, label, depth)
    out = np.column_stack([count, u, v, near, np.broadcast_to(unpack(key), (n, 3))])
    return out[(count >= min_pixels) & np.isfinite(near)]


def unproject(u: np.ndarray, v: np.ndarray, z: np.ndarray, size: tuple[int, int], view_angle: float) -> np.ndarray:
    """Pixel centroids (column ``u``, row ``v`` from the top) at depth ``z`` to eye-frame points (right, up, forward).

    ``view_angle``: the vertical field of view in degrees (the horizontal one follows from the aspect ``size``)."""
    w, h = size
    tan_v = np.tan(np.radians(view_angle) / 2)
    tan_h = tan_v * w / h
    x = (2 * (np.asarray(u) + 0.5) / w - 1) * tan_h * z
    y = (1 - 2 * (np.asarray(v) + 0.5) / h) * tan_v * z
    return np.stack([x, y, np.asarray(z, dtype=float)], axis=-1)
