"""compare and mesh: CLI and Python agree bit for bit; the examples run on a small volume (issue 17)."""
import csv
import json
import os
import subprocess
import sys

import numpy as np
import pytest

import raysift
from conftest import bits, read_exr, run_cli, write_inputs

SOURCE_DIR = os.environ.get("RAYSIFT_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))


def test_compare_gives_the_cli_stats(tmp_path, volume, tf, camera):
    full, _ = raysift.render(volume, tf, camera)
    fast, _ = raysift.render(volume, tf, camera, mode="subsample", ray_fraction=0.2)
    raysift.write_image(str(tmp_path / "a.exr"), full)
    raysift.write_image(str(tmp_path / "b.exr"), fast)
    assert np.array_equal(bits(raysift.read_image(str(tmp_path / "a.exr"))), bits(full))
    done = run_cli("compare", tmp_path / "a.exr", tmp_path / "b.exr", "--stats", tmp_path / "s.json", "--quiet")
    assert done.returncode == 0, done.stderr
    ours = raysift.compare(full, fast)
    assert ours == json.loads((tmp_path / "s.json").read_text())
    assert 0 < ours["ssim_object"] < 1 and ours["object_pixels"] == int((full[..., 3] > 0).sum())
    assert raysift.compare(full, full)["mae"] == 0


def test_compare_with_a_mask_counts_only_its_pixels(volume, tf, camera):
    full, _ = raysift.render(volume, tf, camera)
    mask = np.zeros(full.shape[:2], np.float32)
    mask[:10, :7] = 1
    assert raysift.compare(full, full * 0.5, mask)["object_pixels"] == 70
    with pytest.raises(TypeError, match=r"\(H, W, 4\)"):
        raysift.compare(full[..., :3], full)


def read_binary_ply(path):
    """(vertices (N,3) float32, faces (M,3) int32) of a binary little-endian PLY with float x,y,z first."""
    data = path.read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().splitlines()
    counts = {line.split()[1]: int(line.split()[2]) for line in header if line.startswith("element")}
    vertex_props = []
    for line in header:
        if line.startswith("element"):
            current = line.split()[1]
        elif line.startswith("property") and current == "vertex":
            vertex_props.append(line.split()[1])
    assert "format binary_little_endian" in header[1] and set(vertex_props) == {"float"}
    n, m = counts["vertex"], counts["face"]
    vertices = np.frombuffer(data, np.float32, n * len(vertex_props), end).reshape(n, -1)[:, :3]
    face_dtype = np.dtype([("count", "u1"), ("index", "<i4", 3)])
    faces = np.frombuffer(data, face_dtype, m, end + vertices.itemsize * n * len(vertex_props))
    assert (faces["count"] == 3).all()
    return vertices, faces["index"]


def test_mesh_gives_the_cli_mesh_and_stats(tmp_path, volume, tf):
    vdb, tf_json, _ = write_inputs(tmp_path, volume, tf, raysift.Camera.fit(volume, 8, 8))
    done = run_cli("mesh", vdb, "--tf", tf_json, "--smooth", "4", "--decimate", "0.5", "-o", tmp_path / "m.ply",
                   "--stats", tmp_path / "s.json", "--quiet")
    assert done.returncode == 0, done.stderr
    vertices, faces, stats = raysift.mesh(volume, tf, smooth=4, decimate=0.5)
    assert vertices.dtype == np.float32 and faces.dtype == np.int32 and faces.shape[1] == 3
    cli_vertices, cli_faces = read_binary_ply(tmp_path / "m.ply")
    assert np.array_equal(bits(vertices), bits(cli_vertices)) and np.array_equal(faces, cli_faces)
    cli_stats = json.loads((tmp_path / "s.json").read_text())
    assert stats["iso_values"] == cli_stats["iso_values"] and stats["surfaces"] == cli_stats["surfaces"]
    assert {k: v["triangles"] for k, v in stats["stages"].items()} == \
        {k: v["triangles"] for k, v in cli_stats["stages"].items()}
    assert not vertices.flags.owndata and faces.max() < len(vertices)


def test_mesh_at_given_iso_values_and_its_errors(volume, tf):
    _, faces, stats = raysift.mesh(volume, tf, iso=[0.5], smooth=0, decimate=1.0)
    assert stats["iso_values"] == [0.5] and len(faces) == stats["surfaces"][0]["triangles"]
    with pytest.raises(raysift.InvalidInput, match="data range"):
        raysift.mesh(volume, tf, iso=[7.0])
    with pytest.raises(raysift.InvalidInput, match="decimate"):
        raysift.mesh(volume, tf, decimate=0)


def run_example(name, *args):
    env = dict(os.environ, MPLBACKEND="Agg")
    return subprocess.run([sys.executable, os.path.join(SOURCE_DIR, "examples", name), *map(str, args)],
                          capture_output=True, text=True, env=env, check=False, timeout=60)


def test_tf_experiment_example_runs_on_a_small_volume(tmp_path, volume, tf):
    vdb, tf_json, _ = write_inputs(tmp_path, volume, tf, raysift.Camera.fit(volume, 8, 8))
    done = run_example("tf_experiment.py", "--volume", vdb, "--tf", tf_json, "--segment", "2", "--width", "40",
                       "--height", "30", "--budget-ms", "20", "--out", tmp_path / "plot.png")
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "plot.png").stat().st_size > 1000
    with open(tmp_path / "plot.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 8 and all(0 < float(r["ssim_object"]) <= 1 for r in rows)


def test_quality_metrics_example_scores_a_directory(tmp_path, volume, tf, camera):
    (tmp_path / "refs").mkdir()
    (tmp_path / "tests").mkdir()
    full, _ = raysift.render(volume, tf, camera)
    for name, fraction in (("a.exr", 0.2), ("b.exr", 0.6)):
        raysift.write_image(str(tmp_path / "refs" / name), full)
        test, _ = raysift.render(volume, tf, camera, mode="subsample", ray_fraction=fraction)
        raysift.write_image(str(tmp_path / "tests" / name), test)
    done = run_example("quality_metrics.py", tmp_path / "refs", tmp_path / "tests", "-o", tmp_path / "scores.csv")
    assert done.returncode == 0, done.stderr
    with open(tmp_path / "scores.csv") as f:
        rows = list(csv.DictReader(f))
    assert [r["image"] for r in rows] == ["a.exr", "b.exr"]
    assert float(rows[0]["psnr_object"]) < float(rows[1]["psnr_object"])  # more rays, closer to the reference


def test_lines_give_the_cli_importance_and_segment_counts(tmp_path, volume, tf):
    vertices, faces, _ = raysift.mesh(volume, tf, smooth=4, decimate=0.5)
    camera = raysift.Camera((20, 8, 16), (6, 2.5, 3.5), width=64, height=48)
    vdb, tf_json, cam_json = write_inputs(tmp_path, volume, tf, camera)
    assert run_cli("mesh", vdb, "--tf", tf_json, "--smooth", "4", "--decimate", "0.5", "-o", tmp_path / "m.ply",
                   "--quiet").returncode == 0
    done = run_cli("lines", tmp_path / "m.ply", "--camera", cam_json, "-o", tmp_path / "l.png", "--importance",
                   tmp_path / "imp.exr", "--stats", tmp_path / "s.json", "--quiet")
    assert done.returncode == 0, done.stderr
    segments, importance, stats = raysift.lines(vertices, faces, camera)
    cli_importance = read_exr(tmp_path / "imp.exr")[..., 0]
    assert importance.shape == cli_importance.shape and np.array_equal(bits(importance), bits(cli_importance))
    cli_stats = json.loads((tmp_path / "s.json").read_text())
    assert stats["segments"] == cli_stats["segments"] and stats["mesh_report"] == cli_stats["mesh_report"]
    assert {name: len(s) for name, s in segments.items()} == stats["segments"]
    contours = segments["contours"]
    assert contours.shape[1:] == (2, 2) and len(contours) > 0
    assert (contours[..., 0] >= -1).all() and (contours[..., 0] <= 65).all()  # pixel coordinates of the frame


def test_lines_reject_a_face_naming_a_missing_vertex(volume, tf, camera):
    vertices, faces, _ = raysift.mesh(volume, tf)
    faces = faces.copy()
    faces[3, 1] = len(vertices)
    with pytest.raises(raysift.InvalidInput, match="face 3"):
        raysift.lines(vertices, faces, camera)


def test_sweep_rows_are_the_cli_csv(tmp_path, volume, tf, camera):
    vdb, tf_json, cam_json = write_inputs(tmp_path, volume, tf, camera)
    scene = tmp_path / "scene.json"
    scene.write_text(json.dumps({"volume": vdb.name, "transfer_function": tf_json.name, "camera": cam_json.name}))
    done = run_cli("sweep", scene, "--ray-fractions", "0.2,0.5", "--budgets-ms", "30", "-o", tmp_path / "t.csv",
                   "--quiet")
    assert done.returncode == 0, done.stderr
    rows = raysift.sweep(volume, tf, camera, ray_fractions=[0.2, 0.5], budgets_ms=[30])
    with open(tmp_path / "t.csv") as f:
        cli_rows = list(csv.DictReader(f))
    assert [r["mode"] for r in rows] == [r["mode"] for r in cli_rows]
    assert list(rows[0]) == list(cli_rows[0])  # the CSV's columns, in order
    untimed = ("mode", "ray_fraction", "rays_traced", "psnr", "ssim", "ssim_object", "mae", "flip", "flip_object")
    for ours, cli in zip(rows, cli_rows):
        if ours["budget_ms"]:
            continue  # a budgeted row's rays depend on the clock
        for key in untimed:
            assert ours[key] == (cli[key] if key == "mode" else type(ours[key])(cli[key])), key
