#!/usr/bin/env python3
"""Transfer-function experiment: sweep the opacity of one TF segment over 8 values; at each, render the full frame
and a prioritized frame at a fixed budget, and plot SSIM over the object pixels and the frame time against opacity.

    PYTHONPATH=build/python python3 examples/tf_experiment.py --out tf_experiment.png
"""
import argparse
import csv
import os

import matplotlib

matplotlib.use("Agg")  # files only, no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import raysift  # noqa: E402

DATASETS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "datasets")


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--volume", default=os.path.join(DATASETS, "engine_ct.vdb"))
    p.add_argument("--tf", default=os.path.join(DATASETS, "engine_ct_tf.json"))
    p.add_argument("--segment", type=int, default=3, help="index of the TF control point whose opacity is swept")
    p.add_argument("--opacities", type=float, nargs=8, default=list(np.linspace(0.05, 0.95, 8)))
    p.add_argument("--budget-ms", type=float, default=20.0,
                   help="budget of the prioritized frames (about half a full 480x360 frame on 2 loaded cores)")
    p.add_argument("--width", type=int, default=480)
    p.add_argument("--height", type=int, default=360)
    p.add_argument("--out", default="tf_experiment.png", help="plot (PNG); the rows go to the same name .csv")
    return p.parse_args()


def with_opacity(tf, segment, opacity):
    """The TF with control point `segment`'s opacity replaced."""
    points = tf.points.copy()
    points[segment, 4] = opacity
    return raysift.TransferFunction.from_points(points[:, 0], points[:, 1:4], points[:, 4])


def sweep(args):
    volume = raysift.Volume.load(args.volume)
    base = raysift.TransferFunction.load(args.tf)
    if not 0 <= args.segment < len(base.points):
        raise SystemExit(f"tf_experiment: --segment must be in [0, {len(base.points)}), got {args.segment}")
    camera = raysift.Camera.fit(volume, args.width, args.height)
    rows = []
    for opacity in args.opacities:
        renderer = raysift.Renderer(volume, with_opacity(base, args.segment, opacity))
        full, full_stats = renderer.render(camera)
        fast, fast_stats = renderer.render(camera, mode="prioritized", budget_ms=args.budget_ms)
        metrics = raysift.compare(full, fast)
        rows.append({"opacity": opacity, "ssim_object": metrics["ssim_object"],
                     "full_ms": full_stats["times_ms"]["frame"], "prioritized_ms": fast_stats["times_ms"]["frame"],
                     "ray_fraction": fast_stats["ray_fraction"]})
    return rows


def plot(rows, path, budget_ms):
    opacity = [r["opacity"] for r in rows]
    fig, left = plt.subplots(figsize=(6.4, 4))
    left.plot(opacity, [r["ssim_object"] for r in rows], "o-", color="tab:blue", label="SSIM_object (prioritized)")
    left.set_xlabel("opacity of the swept TF point")
    left.set_ylabel("SSIM over object pixels")
    right = left.twinx()
    right.plot(opacity, [r["full_ms"] for r in rows], "s--", color="tab:red", label="full frame")
    right.plot(opacity, [r["prioritized_ms"] for r in rows], "^--", color="tab:orange",
               label=f"prioritized ({budget_ms:g} ms budget)")
    right.set_ylabel("frame time (ms)")
    fig.legend(loc="lower center", ncol=3, fontsize="small")
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    fig.savefig(path, dpi=100)


def main():
    args = parse_args()
    rows = sweep(args)
    with open(os.path.splitext(args.out)[0] + ".csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    plot(rows, args.out, args.budget_ms)
    print(f"wrote {args.out} and its .csv: {len(rows)} opacities")


if __name__ == "__main__":
    main()
