#!/usr/bin/python3
"""Plots shadows_bench's Fig. 9 CSV (Xie, Wang & Popescu 2016, Fig. 9): end-to-end soft-shadow time against the
grass scene's triangle count for shadow maps of the original geometry and the three discretizations.

  plot_shadows_fig9.py SHADOWS_FIG9.csv OUT.png

Debian's /usr/bin/python3 with python3-matplotlib.
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

LABELS = {"shadowmap": "shadow maps of the geometry (paper: Geometry)", "conventional": "conventional",
          "nrr": "nrr (pixel redundancy)", "peel": "depth peeling", "raytrace": "exact shadow rays (Embree)"}


def main(argv):
    if len(argv) != 3:
        sys.exit(__doc__)
    with open(argv[1], newline="") as f:
        rows = list(csv.DictReader(f))
    n = [int(r["triangles"]) / 1e3 for r in rows]
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for key, label in LABELS.items():
        ax.plot(n, [float(r[key]) / 1e3 for r in rows], "-o", label=label)
    ax.axvline(250, color="grey", linestyle=":", label="paper's crossover (250K)")
    ax.set_xscale("log")
    ax.set_xlabel("grass triangles (thousands)")
    ax.set_ylabel("end-to-end CPU time (s, all threads)")
    ax.set_title("Soft-shadow time vs scene complexity (NRR Fig. 9)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(argv[2], dpi=90)


if __name__ == "__main__":
    main(sys.argv)
