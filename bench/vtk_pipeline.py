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


def smoother(source, iterations):
    s = vtk.vtkWindowedSincPolyDataFilter()
    s.SetInputConnection(source.GetOutputPort())
    s.SetNumberOfIterations(iterations)
    s.BoundarySmoothingOff()
    s.FeatureEdgeSmoothingOff()
    s.NonManifoldSmoothingOff()
    s.SetPassBand(0.1)
    return s


def main(argv):
    if len(argv) != 9:
        sys.exit(__doc__)
    path, nx, ny, nz = argv[1], int(argv[2]), int(argv[3]), int(argv[4])
    isos = [float(v) for v in argv[5].split(",")]
    iterations, keep, runs = int(argv[6]), float(argv[7]), int(argv[8])
    reader = vtk.vtkImageReader2()
    reader.SetFileName(path)
    reader.SetFileDimensionality(3)
    reader.SetDataExtent(0, nx - 1, 0, ny - 1, 0, nz - 1)
    reader.SetDataByteOrderToLittleEndian()
    reader.SetDataScalarTypeToFloat()
    reader.Update()
    chains = []
    for iso in isos:
        fe = vtk.vtkFlyingEdges3D()
        fe.SetInputConnection(reader.GetOutputPort())
        fe.SetValue(0, iso)
        fe.ComputeNormalsOff()
        fe.ComputeGradientsOff()
        fe.ComputeScalarsOff()
        before = smoother(fe, iterations)
        decimate = vtk.vtkQuadricDecimation()
        decimate.SetInputConnection(before.GetOutputPort())
        decimate.SetTargetReduction(1.0 - keep)
        chains.append((fe, smoother(decimate, iterations)))
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
