#!/usr/bin/python3
"""VTK's equivalent of `raysift mesh` for bench/isosurface_bench (bench only; Debian's python3-vtk9).

  vtk_pipeline.py RAW_F32 NX NY NZ ISO[,ISO...] SMOOTH_ITERATIONS KEEP_RATIO RUNS

Per iso-value: vtkFlyingEdges3D -> vtkWindowedSincPolyDataFilter -> vtkQuadricDecimation (keep KEEP_RATIO of the
faces) -> vtkWindowedSincPolyDataFilter, the iso-values one after another (FlyingEdges3D is threaded through
vtkSMPTools; the other filters are serial). Prints "ms=<median wall ms> triangles=<output triangles> threads=<smp>".
"""
import statistics
import sys
import time

import vtk

from vtk_reference import flying_edges_filter, raw_reader, windowed_sinc_filter


def main(argv):
    if len(argv) != 9:
        sys.exit(__doc__)
    path, nx, ny, nz = argv[1], int(argv[2]), int(argv[3]), int(argv[4])
    isos = [float(v) for v in argv[5].split(",")]
    iterations, keep, runs = int(argv[6]), float(argv[7]), int(argv[8])
    reader = raw_reader(path, nx, ny, nz, "f32")
    chains = []
    keep_alive = []  # VTK's pipeline does not own the Python-side filter objects
    for iso in isos:
        fe = flying_edges_filter(reader, iso)
        before = windowed_sinc_filter(fe, iterations)
        decimate = vtk.vtkQuadricDecimation()
        decimate.SetInputConnection(before.GetOutputPort())
        decimate.SetTargetReduction(1.0 - keep)
        keep_alive += [before, decimate]
        chains.append((fe, windowed_sinc_filter(decimate, iterations)))
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        for fe, last in chains:
            fe.Modified()
            last.Update()
        times.append((time.perf_counter() - start) * 1e3)
    triangles = sum(last.GetOutput().GetNumberOfCells() for _, last in chains)
    print(f"ms={statistics.median(times):.3f} triangles={triangles} threads={vtk.vtkSMPTools.GetEstimatedNumberOfThreads()}")


if __name__ == "__main__":
    main(sys.argv)
