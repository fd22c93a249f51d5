#!/usr/bin/python3
"""Plots a `raysift sweep` CSV: error against frame time (the Pareto view) for every mode and knob.

  plot_trade.py TRADE.csv OUT.png TITLE

Series: prioritized / control / subsample over ray fractions, prioritized / control over frame budgets, and the
full render over its sampling step and its early-termination threshold. Left: FLIP over object pixels; right:
1 - SSIM over object pixels; both against frame time (times_ms.frame) with the full render's time marked.
Run by `raysift sweep --plot` with Debian's /usr/bin/python3 and python3-matplotlib.
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def series(rows):
    """Groups rows into (label, rows) by mode and by which knob varies."""
    reference = next(r for r in rows if r["mode"] == "full")
    groups = {}
    for r in rows:
        if r is reference:
            continue
        if r["mode"] == "full":
            knob = "step" if r["step"] != reference["step"] else "early termination"
            label = f"full, {knob}"
        elif float(r["budget_ms"]) > 0:
            label = f"{r['mode']}, budget"
        else:
            label = f"{r['mode']}, ray fraction"
        groups.setdefault(label, []).append(r)
    return reference, groups


def main(argv):
    if len(argv) != 4:
        sys.exit(__doc__)
    with open(argv[1], newline="") as f:
        rows = list(csv.DictReader(f))
    reference, groups = series(rows)
    fig, axes = plt.subplots(1, 2, figsize=(12, 5))
    styles = ["o-", "s--", "^:", "D-", "v--", "x-", "P:"]
    for (label, rs), style in zip(sorted(groups.items()), styles * 2):
        rs = [r for r in rs if r["flip_object"] and r["ssim_object"]]
        rs.sort(key=lambda r: float(r["total_ms"]))
        t = [float(r["total_ms"]) for r in rs]
        axes[0].plot(t, [float(r["flip_object"]) for r in rs], style, label=label)
        axes[1].plot(t, [1 - float(r["ssim_object"]) for r in rs], style, label=label)
    for ax, name in zip(axes, ("FLIP (object pixels)", "1 - SSIM (object pixels)")):
        ax.axvline(float(reference["total_ms"]), color="gray", lw=1)
        ax.set_xlabel("frame time (ms)")
        ax.set_ylabel(name)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(argv[3] + f"  (full render {float(reference['total_ms']):.0f} ms, grey line)")
    fig.tight_layout()
    fig.savefig(argv[2], dpi=110)


if __name__ == "__main__":
    main(sys.argv)
