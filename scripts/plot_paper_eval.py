#!/usr/bin/python3
"""Plots paper_eval_bench's CSV as analogues of the ray-prioritization paper's Fig. 5 and Fig. 7.

  plot_paper_eval.py PAPER_EVAL.csv OUT_PREFIX

Writes OUT_PREFIX_fig5.png and OUT_PREFIX_fig7.png. Every value is prioritized / subsampling error (below 1:
prioritized is better).
- Fig. 5: one row of panels per volume: FLIP, 1 - SSIM (RGB, object pixels) and alpha MAE (Weiss et al. 2020's
  separate alpha score), each against the ray fraction, one line per classifier, solid at equal frame time and
  dotted at equal rays. Hollow markers: the prioritized frame's time fell outside subsampling's measured curve.
- Fig. 7: FLIP and 1 - SSIM at a guaranteed frame rate (budget mode at 2-16x the full render's rate), one line
  per volume, against subsampling at the same frame time (hollow markers: outside subsampling's curve).
Debian's /usr/bin/python3 with python3-matplotlib.
"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

METRICS = [("flip_ratio", "FLIP"), ("dssim_ratio", "1 - SSIM"), ("alpha_ratio", "alpha MAE")]


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def ordered(values):
    """Distinct values in first-seen order (the bench's order of volumes and classifiers)."""
    return list(dict.fromkeys(values))


def fig5(rows, out):
    rows = [r for r in rows if r["figure"] == "fig5"]
    scenes = ordered(r["scene"] for r in rows)
    classifiers = ordered(r["series"] for r in rows)
    colours = {c: plt.cm.tab10(i) for i, c in enumerate(classifiers)}
    fig, axes = plt.subplots(len(scenes), len(METRICS), figsize=(5 * len(METRICS), 3.6 * len(scenes)), squeeze=False)
    for row, scene in enumerate(scenes):
        for col, (key, label) in enumerate(METRICS):
            ax = axes[row][col]
            for c in classifiers:
                for basis, style in (("equal_time", "-"), ("equal_rays", ":")):
                    points = defaultdict(list)
                    for r in rows:
                        if r["scene"] == scene and r["series"] == c and r["basis"].startswith(basis):
                            points["x"].append(float(r["x"]))
                            points["y"].append(float(r[key]))
                            points["clamped"].append(r["basis"].endswith("clamped"))
                    if not points["x"]:
                        continue
                    ax.plot(points["x"], points["y"], style, color=colours[c],
                            label=c if basis == "equal_time" else None)
                    for x, y, clamped in zip(points["x"], points["y"], points["clamped"]):
                        ax.plot([x], [y], "o", color=colours[c], markersize=3.5,
                                markerfacecolor="none" if clamped else colours[c])
            ax.axhline(1.0, color="black", linewidth=0.8)
            ax.set_xscale("log")
            ax.set_xticks([2, 5, 10, 20, 40])
            ax.set_xticklabels(["2", "5", "10", "20", "40"])
            ax.set_xlabel("rays, % of the full render")
            ax.set_ylabel(f"{label}: prioritized / subsample")
            ax.set_title(f"{scene}: {label}")
            ax.grid(True, alpha=0.3)
    axes[0][0].legend(fontsize=7, title="solid: equal time; dotted: equal rays", title_fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def fig7(rows, out):
    rows = [r for r in rows if r["figure"] == "fig7"]
    scenes = ordered(r["scene"] for r in rows)
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    for ax, (key, label) in zip(axes, METRICS[:2]):
        for scene in scenes:
            mine = [r for r in rows if r["scene"] == scene]
            line, = ax.plot([float(r["x"]) for r in mine], [float(r[key]) for r in mine], "-", label=scene)
            for r in mine:
                ax.plot([float(r["x"])], [float(r[key])], "o", color=line.get_color(),
                        markerfacecolor="none" if r["basis"].endswith("clamped") else line.get_color())
        ax.axhline(1.0, color="black", linewidth=0.8)
        ax.set_xscale("log", base=2)
        ax.set_xlabel("guaranteed frame rate, x the full render's")
        ax.set_ylabel(f"{label}: prioritized / subsample at the same time")
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: plot_paper_eval.py PAPER_EVAL.csv OUT_PREFIX")
    rows = read(sys.argv[1])
    fig5(rows, sys.argv[2] + "_fig5.png")
    fig7(rows, sys.argv[2] + "_fig7.png")


if __name__ == "__main__":
    main()
