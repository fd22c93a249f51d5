#!/usr/bin/python3
"""Plots nrr_fig7_bench's CSV as the paper's Fig. 7 (Xie, Wang & Popescu 2016) plus the availability gap.

  plot_nrr_fig7.py NRR_FIG7.csv OUT.png

One row of panels per scene: redundant samples of conventional images 1 and 2, disoccluded and useful samples of
NRR images 1 and 2 (pixel metric: nrr-pixel images; visibility metric: nrr-visibility images), each against the
image resolution, and the availability gap (conventional minus nrr-pixel, metric (4) with pixel redundancy) with
the 1-point line of issue 14, by the paper's exact pixel test and, where the CSV has them, on a quarter of the
frames by the exact test and by the footprint-tolerant test (the triangle within one pixel of the projection). Debian's /usr/bin/python3 with python3-matplotlib.
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

PANELS = [("conv_redundant", "redundant (conventional) %"), ("nrr_disoccluded", "disoccluded (NRR) %"),
          ("nrr_useful", "useful (NRR), % of disoccluded")]


def main(argv):
    if len(argv) != 3:
        sys.exit(__doc__)
    with open(argv[1], newline="") as f:
        rows = list(csv.DictReader(f))
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    fig, axes = plt.subplots(len(scenes), 4, figsize=(17, 3.8 * len(scenes)), squeeze=False)
    for si, scene in enumerate(scenes):
        for metric, style in (("pixel", "-"), ("visibility", "--")):
            rs = sorted((r for r in rows if r["scene"] == scene and r["metric"] == metric),
                        key=lambda r: int(r["resolution"]))
            res = [int(r["resolution"]) for r in rs]
            for pi, (key, title) in enumerate(PANELS):
                for img, marker in ((1, "o"), (2, "s")):
                    axes[si][pi].plot(res, [float(r[f"{key}_{img}"]) for r in rs], style + marker,
                                      label=f"{metric}, image {img}")
                axes[si][pi].set_title(f"{scene}: {title}")
            if metric == "pixel":
                gap = [float(r["conv_available_avg"]) - float(r["nrr_available_avg"]) for r in rs]
                axes[si][3].plot(res, gap, "-o", label="conv - nrr-pixel, exact pixel test (all frames)")
                sub = [r for r in rs if r.get("conv_available_exact_sub", "nan") != "nan"]
                if sub:
                    sres = [int(r["resolution"]) for r in sub]
                    for kind, marker, label in (("exact", "x", "exact pixel test (1/4 of frames)"),
                                                ("1px", "^", "footprint-tolerant: within 1 px (1/4 of frames)")):
                        axes[si][3].plot(sres, [float(r[f"conv_available_{kind}_sub"]) -
                                                float(r[f"nrr_available_{kind}_sub"]) for r in sub],
                                         "--" + marker, label=label)
                axes[si][3].axhline(1.0, color="grey", linestyle=":", label="1 point")
                axes[si][3].axhline(0.0, color="black", linewidth=0.5)
                axes[si][3].set_title(f"{scene}: availability gap, pixel metric")
        for ax in axes[si]:
            ax.set_xscale("log", base=2)
            ax.set_xticks([256, 512, 1024, 1536, 2048])
            ax.set_xticklabels(["256", "512", "1024", "1536", "2048"])
            ax.set_xlabel("image side (pixels)")
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(argv[2], dpi=90)


if __name__ == "__main__":
    main(sys.argv)
