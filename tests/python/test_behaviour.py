"""What users rely on: zero-copy results, the GIL released, exceptions mapped, Ctrl-C, no leak (issue 17 item 3)."""
import gc
import os
import signal
import threading
import time

import numpy as np
import pytest

import raysift
from conftest import asymmetric_array


def big_camera(volume, side):
    return raysift.Camera.fit(volume, side, side)


def test_the_image_is_a_view_on_the_render_buffer_that_outlives_the_renderer(volume, tf, camera):
    renderer = raysift.Renderer(volume, tf)
    image, _ = renderer.render(camera)
    assert not image.flags.owndata and image.base is not None  # no copy: a capsule owns the buffer
    assert image.flags.c_contiguous
    kept = image.copy()
    del renderer
    gc.collect()
    for _ in range(3):  # fresh allocations would reuse a freed buffer
        raysift.render(volume, tf, camera)
    assert np.array_equal(image, kept)


def test_to_numpy_is_a_view_too(volume):
    array = volume.to_numpy()
    assert not array.flags.owndata and array.base is not None


def test_a_python_thread_keeps_running_during_a_render(volume, tf):
    camera = big_camera(volume, 360)
    start = time.perf_counter()
    raysift.render(volume, tf, camera, step=0.1, threads=1)
    alone = time.perf_counter() - start
    count, stop = [0], threading.Event()

    def counter():
        while not stop.is_set():
            count[0] += 1

    thread = threading.Thread(target=counter)
    thread.start()
    time.sleep(0.01)
    before = count[0]
    raysift.render(volume, tf, camera, step=0.1, threads=1)
    during = count[0] - before
    stop.set()
    thread.join()
    assert alone > 0.05, "the render must be long enough for the counter to be measured"
    # With the GIL held the counter would stand still but for the interpreter's switch at each 50 ms wake-up.
    assert during > 10000, f"counter advanced {during} times during a {alone:.2f} s render"


def test_io_errors_are_raysift_ioerror_an_oserror(tmp_path):
    with pytest.raises(raysift.IOError, match="missing.vdb"):
        raysift.Volume.load(str(tmp_path / "missing.vdb"))
    assert issubclass(raysift.IOError, OSError)
    with pytest.raises(OSError):
        raysift.TransferFunction.load(str(tmp_path / "none.json"))
    with pytest.raises(raysift.IOError):
        raysift.Volume.from_numpy(asymmetric_array()).save(str(tmp_path / "no" / "dir" / "v.vdb"))


def test_invalid_inputs_are_raysift_invalidinput_a_valueerror(tmp_path, volume, tf, camera):
    assert issubclass(raysift.InvalidInput, ValueError)
    (tmp_path / "bad.json").write_text('{"points": [[1, 0, 0, 0, 0], [0, 0, 0, 0, 0]]}')
    with pytest.raises(raysift.InvalidInput, match="bad.json"):
        raysift.TransferFunction.load(str(tmp_path / "bad.json"))
    with pytest.raises(raysift.InvalidInput, match="mode"):
        raysift.render(volume, tf, camera, mode="fast")
    with pytest.raises(raysift.InvalidInput, match="shading"):
        raysift.render(volume, tf, camera, shading="toon")
    with pytest.raises(raysift.InvalidInput, match="budget_ms"):
        raysift.render(volume, tf, camera, budget_ms=5)
    with pytest.raises(raysift.InvalidInput):
        raysift.render(volume, tf, camera, mode="prioritized", ray_fraction=1.5)
    with pytest.raises(raysift.InvalidInput):
        raysift.render(volume, tf, camera, step=0)
    with pytest.raises(raysift.InvalidInput):
        raysift.render(volume, tf, camera, mode="prioritized", features="curls")
    with pytest.raises(raysift.InvalidInput):
        raysift.Camera((0, 0, 5), (0, 0, 5))
    with pytest.raises(raysift.InvalidInput):
        raysift.Camera((0, 0, 5), (0, 0, 0), width=0)
    with pytest.raises(raysift.InvalidInput):
        raysift.TransferFunction.from_points([0, 1], [[0, 0, 0], [2, 0, 0]], [0, 1])


def test_type_errors_name_what_was_expected(volume, tf, camera):
    with pytest.raises(TypeError, match="background"):
        raysift.render(volume, tf, camera, background=(0, 0))
    with pytest.raises(TypeError, match=r"\(N, 3\)"):
        raysift.TransferFunction.from_points([0, 1], [0, 1], [0, 1])


def test_ctrl_c_during_a_render_raises_keyboardinterrupt_within_a_second(volume, tf):
    camera = big_camera(volume, 1600)
    fired = []

    def interrupt():
        fired.append(time.perf_counter())
        os.kill(os.getpid(), signal.SIGINT)

    timer = threading.Timer(0.3, interrupt)
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        raysift.render(volume, tf, camera, step=0.02, threads=1)
    timer.join()
    assert time.perf_counter() - fired[0] < 1.0
    image, _ = raysift.render(volume, tf, raysift.Camera.fit(volume, 8, 8))  # the next render is not cancelled
    assert image.shape == (8, 8, 4)


def rss_bytes():
    with open("/proc/self/statm") as statm:
        return int(statm.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def test_memory_does_not_grow_over_200_renders(volume, tf):
    camera = raysift.Camera.fit(volume, 96, 96)  # 147 KB per image: a leaked frame per render would add 29 MB
    renderer = raysift.Renderer(volume, tf)
    for _ in range(20):
        renderer.render(camera, mode="prioritized", ray_fraction=0.3)
    gc.collect()
    before = rss_bytes()
    for i in range(100):  # both entry points, both kinds of mode
        keywords = {"mode": "prioritized", "ray_fraction": 0.3} if i % 2 else {}
        image, stats = renderer.render(camera, **keywords)
        image, stats = raysift.render(volume, tf, camera, **keywords)
    del image, stats
    gc.collect()
    assert rss_bytes() - before < 4 * 1024 * 1024


def test_the_cli_warnings_are_runtime_warnings(volume, tf, camera):
    invisible = raysift.TransferFunction.from_points([0.0, 1.0], [[1, 1, 1], [1, 1, 1]], [0.0, 0.0])
    with pytest.warns(RuntimeWarning, match="transparent over the whole data range"):
        raysift.render(volume, invisible, camera, mode="prioritized", ray_fraction=0.5)
    with pytest.warns(RuntimeWarning, match="only level 0 was traced"):
        raysift.render(volume, tf, camera, mode="prioritized", budget_ms=1e-6)
