#!/usr/bin/env python3
"""Python module vs CLI (issue 17 benchmark), timed in the same run:
1. N cameras (an orbit) of the bundled engine CT through one raysift.Renderer, vs N `raysift render` calls (each
   a process: start-up, volume load, render, EXR write) -- the ratio is what a notebook gains;
2. the per-call overhead of the binding: wall time of Renderer.render minus the C++ time inside it
   (cpp_ms), at the benchmark size and at 8x8 where the render itself is negligible.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_bench.py --exe build/raysift
"""
import argparse
import json
import math
import os
import statistics
import subprocess
import tempfile
import time

import raysift

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--exe", default=os.path.join(ROOT, "build", "raysift"))
    p.add_argument("--volume", default=os.path.join(ROOT, "datasets", "engine_ct.vdb"))
    p.add_argument("--tf", default=os.path.join(ROOT, "datasets", "engine_ct_tf.json"))
    p.add_argument("--cameras", type=int, default=100)
    p.add_argument("--size", type=int, default=256, help="image side, pixels")
    p.add_argument("--mode", default="full", choices=["full", "prioritized", "subsample"])
    p.add_argument("--ray-fraction", type=float, default=0.3, help="sampled modes")
    return p.parse_args()


def orbit(volume, count, side):
    """`count` cameras on a circle around the default view's target, at its distance."""
    fit = raysift.Camera.fit(volume, side, side)
    target, eye = fit.target, fit.eye
    radius = math.dist(eye, target)
    return [raysift.Camera((target[0] + radius * math.cos(a), eye[1], target[2] + radius * math.sin(a)), target,
                           fov_y_deg=fit.fov_y_deg, width=side, height=side)
            for a in (2 * math.pi * i / count for i in range(count))]


def cpp_ms(stats):
    """The C++ time inside one call: a sampled frame's times_ms.total is the frame alone (the CLI's contract)."""
    t = stats["times_ms"]
    return t["total"] if stats["mode"] == "full" else t["setup"] + t["features_setup"] + t["total"]


def keywords(args):
    return {"mode": args.mode} if args.mode == "full" else {"mode": args.mode, "ray_fraction": args.ray_fraction}


def time_python(args, cameras):
    start = time.perf_counter()
    renderer = raysift.Renderer(raysift.Volume.load(args.volume), raysift.TransferFunction.load(args.tf))
    overhead = []
    for camera in cameras:
        call = time.perf_counter()
        _, stats = renderer.render(camera, **keywords(args))
        overhead.append((time.perf_counter() - call) * 1e3 - cpp_ms(stats))
    return time.perf_counter() - start, renderer, overhead


def time_cli(args, cameras, folder):
    flags = ["--mode", args.mode] + ([] if args.mode == "full" else ["--ray-fraction", str(args.ray_fraction)])
    paths = []
    for i, camera in enumerate(cameras):
        paths.append(os.path.join(folder, f"camera_{i}.json"))
        with open(paths[-1], "w") as f:
            json.dump(camera.to_dict(), f)
    start = time.perf_counter()
    for path in paths:
        subprocess.run([args.exe, "render", args.volume, "--tf", args.tf, "--camera", path, "-o",
                        os.path.join(folder, "out.exr"), "--quiet", *flags], check=True)
    return time.perf_counter() - start


def small_overhead(renderer, volume, repeats=200):
    camera = raysift.Camera.fit(volume, 8, 8)
    overhead, walls = [], []
    for _ in range(repeats):
        call = time.perf_counter()
        _, stats = renderer.render(camera)
        walls.append((time.perf_counter() - call) * 1e3)
        overhead.append(walls[-1] - cpp_ms(stats))
    return statistics.median(overhead), statistics.median(walls)


def main():
    args = parse_args()
    volume = raysift.Volume.load(args.volume)
    cameras = orbit(volume, args.cameras, args.size)
    with tempfile.TemporaryDirectory() as folder:
        cli_s = time_cli(args, cameras, folder)
    py_s, renderer, overhead = time_python(args, cameras)
    small, small_wall = small_overhead(renderer, volume)
    print(f"load: {os.getloadavg()[0]:.2f} (1-min average, {os.cpu_count()} cores)")
    print(f"{args.cameras} cameras {args.size}x{args.size} {args.mode}: CLI {cli_s:.2f} s ({cli_s / args.cameras * 1e3:.1f} "
          f"ms/call), Renderer {py_s:.2f} s ({py_s / args.cameras * 1e3:.1f} ms/call incl. one load), "
          f"ratio CLI/Python {cli_s / py_s:.2f}")
    print(f"binding overhead per call (wall - C++ time): median {statistics.median(overhead):.3f} ms at "
          f"{args.size}x{args.size}; {small:.3f} ms of {small_wall:.3f} ms at 8x8")


if __name__ == "__main__":
    main()
