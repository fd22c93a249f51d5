"""Shared fixtures of the Python tests: a small volume with an asymmetric feature, its TF and camera, and the CLI."""
import json
import os
import subprocess

import numpy as np
import pytest

import raysift

RAYSIFT_EXE = os.environ.get("RAYSIFT_EXE", "raysift")


def asymmetric_array(dtype=np.float32):
    """[z, y, x] = 14 x 18 x 22: a ball off-centre plus a bar along +x only, so any axis swap or flip shows."""
    z, y, x = np.mgrid[0:14, 0:18, 0:22].astype(np.float64)
    ball = np.clip(1.0 - np.sqrt((x - 7) ** 2 + (y - 8) ** 2 + (z - 6) ** 2) / 5.0, 0, None)
    bar = ((x > 9) & (x < 20) & (np.abs(y - 12) < 2) & (np.abs(z - 4) < 2)) * 0.8
    values = np.maximum(ball, bar)
    if np.issubdtype(dtype, np.integer):
        return (values * 200).astype(dtype)
    return values.astype(dtype)


@pytest.fixture
def volume():
    return raysift.Volume.from_numpy(asymmetric_array(), voxel_size=0.5, origin=(1.0, -2.0, 0.5))


@pytest.fixture
def tf():
    return raysift.TransferFunction.from_points(
        [0.0, 0.2, 0.6, 1.0], [[0, 0, 0], [0.9, 0.5, 0.2], [0.2, 0.6, 1.0], [1, 1, 1]], [0.0, 0.05, 0.4, 0.9])


@pytest.fixture
def camera(volume):
    return raysift.Camera.fit(volume, 48, 36)


def run_cli(*args):
    """Runs the raysift executable; returns the completed process (stderr captured)."""
    return subprocess.run([RAYSIFT_EXE, *map(str, args)], capture_output=True, text=True, check=False)


def write_inputs(tmp_path, volume, tf, camera):
    """The Python inputs as the files the CLI reads: (volume.vdb, tf.json, camera.json)."""
    paths = tmp_path / "volume.vdb", tmp_path / "tf.json", tmp_path / "camera.json"
    volume.save(str(paths[0]))
    paths[1].write_text(json.dumps([tf.to_paraview()]))
    paths[2].write_text(json.dumps(camera.to_dict()))
    return paths


def read_exr(path):
    """(H, W, 4) float32 pixels of an EXR, through OpenImageIO's Python binding (python3-openimageio)."""
    oiio = pytest.importorskip("OpenImageIO")
    image = oiio.ImageInput.open(str(path))
    assert image, f"cannot open {path}"
    pixels = image.read_image(format="float")
    image.close()
    return np.asarray(pixels, dtype=np.float32)


def bits(array):
    """Bit patterns, so -0.0 != 0.0 and NaN == NaN: equality means bit-identical."""
    return np.ascontiguousarray(array, dtype=np.float32).view(np.uint32)
