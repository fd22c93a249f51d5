"""from_numpy / to_numpy: axis order [z, y, x] against the raw importer, dtypes, copies and the type errors."""
import numpy as np
import pytest

import raysift
from conftest import asymmetric_array, bits, run_cli


def test_to_numpy_returns_the_array_over_its_active_box():
    array = asymmetric_array()
    back = raysift.Volume.from_numpy(array).to_numpy()
    nz = np.argwhere(array != 0)
    lo, hi = nz.min(axis=0), nz.max(axis=0) + 1
    assert back.dtype == np.float32
    assert np.array_equal(back, array[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]])


def test_info_names_the_active_box_in_x_y_z_order():
    info = raysift.Volume.from_numpy(asymmetric_array(), voxel_size=0.5).info()
    nz = np.argwhere(asymmetric_array() != 0)
    assert info["index_min"] == nz.min(axis=0)[::-1].tolist()  # [z, y, x] in NumPy, x, y, z in raysift
    assert info["index_max"] == nz.max(axis=0)[::-1].tolist()
    assert info["voxel_size"] == [0.5, 0.5, 0.5]
    assert info["active_voxels"] == int((asymmetric_array() != 0).sum())


@pytest.mark.parametrize("dtype,cli_type", [(np.float32, "f32"), (np.float64, "f64"), (np.uint8, "u8"),
                                            (np.uint16, "u16")])
def test_from_numpy_renders_as_the_raw_import_of_the_same_bytes(tmp_path, tf, dtype, cli_type):
    array = asymmetric_array(dtype)
    raw, vdb = tmp_path / "v.raw", tmp_path / "v.vdb"
    raw.write_bytes(array.tobytes(order="C"))
    z, y, x = array.shape
    done = run_cli("import", raw, "--dims", f"{x},{y},{z}", "--type", cli_type, "-o", vdb, "--quiet")
    assert done.returncode == 0, done.stderr
    imported = raysift.Volume.load(str(vdb))
    ours = raysift.Volume.from_numpy(array)
    assert np.array_equal(ours.to_numpy(), imported.to_numpy())
    scale = 200.0 if np.issubdtype(dtype, np.integer) else 1.0
    tf_scaled = raysift.TransferFunction.from_points([0, 0.3 * scale, scale], [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
                                                     [0, 0.3, 0.8])
    camera = raysift.Camera((30, 10, 8), (11, 9, 7), width=32, height=24)
    a, _ = raysift.render(ours, tf_scaled, camera)
    b, _ = raysift.render(imported, tf_scaled, camera)
    assert a[..., 3].max() > 0.1
    assert np.array_equal(bits(a), bits(b))


def test_a_flipped_array_is_a_different_volume():
    array = asymmetric_array()
    flipped = raysift.Volume.from_numpy(array[:, :, ::-1]).to_numpy()  # non-contiguous: copied once, not rejected
    assert not np.array_equal(flipped, raysift.Volume.from_numpy(array).to_numpy())
    assert np.array_equal(flipped, raysift.Volume.from_numpy(np.ascontiguousarray(array[:, :, ::-1])).to_numpy())


def test_tolerance_and_background_decide_the_active_voxels():
    array = np.full((8, 8, 8), 5.0, np.float32)
    array[2, 3, 4] = 5.5
    volume = raysift.Volume.from_numpy(array, background=5.0, tolerance=0.25)
    assert volume.info()["active_voxels"] == 1 and volume.info()["index_min"] == [4, 3, 2]


@pytest.mark.parametrize("bad", [np.zeros((4, 4), np.float32), np.zeros((2, 2, 2, 2), np.float32),
                                 np.zeros((4, 4, 4), np.int32), np.zeros((4, 4, 4), np.complex64)])
def test_wrong_shape_or_dtype_is_a_type_error_naming_the_expected_shape(bad):
    with pytest.raises(TypeError, match=r"3-D \[z, y, x\] array"):
        raysift.Volume.from_numpy(bad)


def test_nan_voxel_is_invalid_input_naming_it():
    array = np.ones((4, 5, 6), np.float32)
    array[1, 2, 3] = np.nan
    with pytest.raises(raysift.InvalidInput, match=r"z=1, y=2, x=3"):
        raysift.Volume.from_numpy(array)


def test_transfer_function_samples_its_points_and_round_trips_paraview():
    tf = raysift.TransferFunction.from_points([0, 1], [[0, 0, 0], [1, 0.5, 0]], [0, 1])
    rgba = tf.sample([0.0, 0.5, 1.0, 2.0])
    assert rgba.shape == (4, 4) and rgba.dtype == np.float32
    assert np.allclose(rgba[1], [0.5, 0.25, 0, 0.5]) and np.array_equal(rgba[3], rgba[2])
    preset = tf.to_paraview()
    assert preset["RGBPoints"][:4] == [0, 0, 0, 0]


def test_histogram_counts_the_active_voxels():
    array = asymmetric_array()
    h = raysift.Volume.from_numpy(array).histogram(bins=16)
    assert len(h["counts"]) == 16 and int(h["counts"].sum()) == int((array != 0).sum())
