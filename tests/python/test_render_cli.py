"""CLI and Python give bit-identical pixels and the same stats for each render mode (issue 17 tests)."""
import json

import numpy as np
import pytest

import raysift
from conftest import bits, read_exr, run_cli, write_inputs

TIMING_KEYS = {"times_ms", "features_setup_ms", "overshoot_ms", "budget_too_small"}

CASES = {
    "full": ([], {}),
    "full-phong": (["--shading", "phong", "--step", "0.25", "--background", "0.1,0.2,0.3"],
                   {"shading": "phong", "step": 0.25, "background": (0.1, 0.2, 0.3)}),
    "prioritized": (["--mode", "prioritized", "--ray-fraction", "0.3", "--seed", "7"],
                    {"mode": "prioritized", "ray_fraction": 0.3, "seed": 7}),
    "prioritized-nofeatures": (["--mode", "prioritized", "--ray-fraction", "0.5", "--features", "none"],
                               {"mode": "prioritized", "ray_fraction": 0.5, "features": "none"}),
    "subsample": (["--mode", "subsample", "--ray-fraction", "0.25"], {"mode": "subsample", "ray_fraction": 0.25}),
}


def untimed(stats):
    return {k: v for k, v in stats.items() if k not in TIMING_KEYS}


@pytest.mark.parametrize("case", sorted(CASES))
def test_cli_and_python_render_the_same_pixels_and_stats(tmp_path, volume, tf, camera, case):
    flags, keywords = CASES[case]
    vdb, tf_json, cam_json = write_inputs(tmp_path, volume, tf, camera)
    out, stats_path = tmp_path / "out.exr", tmp_path / "stats.json"
    done = run_cli("render", vdb, "--tf", tf_json, "--camera", cam_json, "-o", out, "--stats", stats_path,
                   "--quiet", "--threads", "2", *flags)
    assert done.returncode == 0, done.stderr
    image, stats = raysift.render(volume, tf, camera, threads=2, **keywords)
    assert image.shape == (36, 48, 4) and image.dtype == np.float32
    cli = read_exr(out)
    assert np.array_equal(bits(image), bits(cli))
    assert image[..., 3].max() > 0.1, "the volume must be visible, or the comparison proves little"
    cli_stats = json.loads(stats_path.read_text())
    assert untimed(stats) == untimed(cli_stats)
    assert set(stats) == set(cli_stats)
    assert set(stats["times_ms"]) == set(cli_stats["times_ms"])


def test_a_renderer_session_gives_what_render_gives_for_many_cameras(volume, tf):
    renderer = raysift.Renderer(volume, tf)
    for i, eye in enumerate([(30, 5, 5), (-4, 25, 9), (5, -3, -30)]):
        camera = raysift.Camera(eye, (6, 2.5, 3.5), width=40, height=30 + i)
        for keywords in ({}, {"mode": "prioritized", "ray_fraction": 0.4}):
            a, sa = renderer.render(camera, **keywords)
            b, sb = raysift.render(volume, tf, camera, **keywords)
            assert np.array_equal(bits(a), bits(b))
            assert sa["rays_traced"] == sb["rays_traced"]
            assert a[..., 3].max() > 0


def test_one_and_two_threads_are_bit_identical(volume, tf, camera):
    for mode in ("full", "prioritized"):
        one, _ = raysift.render(volume, tf, camera, mode=mode, ray_fraction=0.3, threads=1)
        two, _ = raysift.render(volume, tf, camera, mode=mode, ray_fraction=0.3, threads=2)
        assert np.array_equal(bits(one), bits(two))
