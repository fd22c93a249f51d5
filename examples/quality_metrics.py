#!/usr/bin/env python3
"""Score a directory of images against references into a CSV: one row per test image whose file name also exists
in the reference directory, with the keys of `raysift compare --stats` as columns.

    PYTHONPATH=build/python python3 examples/quality_metrics.py refs/ tests/ -o scores.csv
"""
import argparse
import csv
import os
import sys

import raysift

IMAGE_EXTENSIONS = (".exr", ".png")


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("references", help="directory of reference images (their alpha > 0 marks the object pixels)")
    p.add_argument("tests", help="directory of test images, matched to the references by file name")
    p.add_argument("-o", "--out", required=True, help="CSV output")
    return p.parse_args()


def score(references, tests):
    rows = []
    for name in sorted(os.listdir(tests)):
        if not name.lower().endswith(IMAGE_EXTENSIONS):
            continue
        ref_path = os.path.join(references, name)
        if not os.path.exists(ref_path):
            print(f"quality_metrics: warning: no reference {ref_path}; skipped", file=sys.stderr)
            continue
        metrics = raysift.compare(raysift.read_image(ref_path), raysift.read_image(os.path.join(tests, name)))
        rows.append({"image": name, **metrics})
    return rows


def main():
    args = parse_args()
    rows = score(args.references, args.tests)
    if not rows:
        sys.exit(f"quality_metrics: error: no test image in {args.tests} has a reference in {args.references}")
    with open(args.out, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    print(f"wrote {args.out}: {len(rows)} images")


if __name__ == "__main__":
    main()
