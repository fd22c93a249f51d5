"""raysift: prioritized volume ray casting from Python (docs/python.md).

NumPy arrays in and out: volumes are indexed [z, y, x] (x fastest, like the raw importer), images [row, column, RGBA]
with row 0 at the top, premultiplied RGBA as in raysift's EXR files.
"""
import csv as _csv
import io as _io

from . import _raysift
from ._raysift import (  # noqa: F401
    Camera,
    InvalidInput,
    IOError,
    Renderer,
    TransferFunction,
    Volume,
    __version__,
    compare,
    lines,
    mesh,
    read_image,
    write_image,
)

__all__ = ["Camera", "InvalidInput", "IOError", "Renderer", "TransferFunction", "Volume", "compare", "lines",
           "mesh", "read_image", "render", "sweep", "write_image"]


def render(volume, tf, camera, **keywords):
    """One `raysift render` of `volume` with `tf` from `camera`: (image (H, W, 4) float32, stats dict).

    The keywords are Renderer.render's; a Renderer keeps the set-up for many cameras.
    """
    return Renderer(volume, tf).render(camera, **keywords)


def sweep(volume, tf, camera, ray_fractions=None, budgets_ms=(), *, features=_raysift._DEFAULT_FEATURES, alpha=None,
          shading="phong", repeats=1, seed=1):
    """`raysift sweep`'s rows: the full render, then prioritized, control and subsample at each ray fraction (and
    prioritized and control at each budget), each a dict with the CSV's columns (numbers as float, empty as None)."""
    fractions = _raysift._SWEEP_RAY_FRACTIONS if ray_fractions is None else list(ray_fractions)
    text = _raysift._sweep_csv(volume, tf, camera, fractions, list(budgets_ms), features, alpha, shading, repeats,
                               seed)
    return [{key: _cell(key, value) for key, value in row.items()} for row in _csv.DictReader(_io.StringIO(text))]


def _cell(key, value):
    if key == "mode":
        return value
    if value == "":
        return None
    return int(value) if key == "rays_traced" else float(value)
