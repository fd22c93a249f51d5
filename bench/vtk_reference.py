#!/usr/bin/python3
"""VTK reference timings for bench/marching_cubes_bench and bench/mesh_prep_bench (bench only).

Run with Debian's interpreter (/usr/bin/python3, package python3-vtk9). Each mode prints one line
"ms=<median wall ms> triangles=<output triangles> ..." that the C++ benches parse (flying-edges: the minimum).

  vtk_reference.py flying-edges RAW[.gz] NX NY NZ u8|f32 ISO RUNS [PAD THREADS]
      PAD > 0: the file has a PAD-voxel background border; also time the interior without it.
      THREADS: vtkSMPTools thread count (0 = VTK's default).
  vtk_reference.py windowed-sinc MESH.ply ITERATIONS RUNS
  vtk_reference.py quadric-decimation MESH.ply TARGET_TRIANGLES RUNS [OUT.ply]
    (OUT.ply: the decimated mesh as binary PLY, so the C++ bench measures its distances with its own code)
"""
import gzip
import os
import shutil
import statistics
import sys
import tempfile
import time

import vtk


def timed(algorithm, runs, stat=statistics.median):
    times = []
    for _ in range(runs):
        algorithm.Modified()
        start = time.perf_counter()
        algorithm.Update()
        times.append((time.perf_counter() - start) * 1e3)
    return stat(times)


def raw_reader(path, nx, ny, nz, dtype):
    """A headerless little-endian raw grid (u8 or f32, x fastest), read once."""
    reader = vtk.vtkImageReader2()
    reader.SetFileName(path)
    reader.SetFileDimensionality(3)
    reader.SetDataExtent(0, nx - 1, 0, ny - 1, 0, nz - 1)
    reader.SetDataByteOrderToLittleEndian()
    if dtype == "u8":
        reader.SetDataScalarTypeToUnsignedChar()
    else:
        reader.SetDataScalarTypeToFloat()
    reader.Update()
    return reader


def flying_edges_filter(source, iso):
    """vtkFlyingEdges3D at one iso-value, positions only (what our marching cubes produces)."""
    fe = vtk.vtkFlyingEdges3D()
    fe.SetInputConnection(source.GetOutputPort())
    fe.SetValue(0, iso)
    fe.ComputeNormalsOff()
    fe.ComputeGradientsOff()
    fe.ComputeScalarsOff()
    return fe


def windowed_sinc_filter(source, iterations):
    """vtkWindowedSincPolyDataFilter with the settings comparable to our Taubin smoothing."""
    smoother = vtk.vtkWindowedSincPolyDataFilter()
    smoother.SetInputConnection(source.GetOutputPort())
    smoother.SetNumberOfIterations(iterations)
    smoother.BoundarySmoothingOff()
    smoother.FeatureEdgeSmoothingOff()
    smoother.NonManifoldSmoothingOff()
    smoother.SetPassBand(0.1)
    return smoother


def flying_edges(path, nx, ny, nz, dtype, iso, runs, pad, threads):
    """FlyingEdges3D on the whole file and, if pad > 0, also on its interior without the pad-voxel border."""
    vtk.vtkSMPTools.Initialize(threads)
    tmp = None
    if path.endswith(".gz"):
        tmp = tempfile.NamedTemporaryFile(suffix=".raw", delete=False)
        with gzip.open(path, "rb") as src:
            shutil.copyfileobj(src, tmp)
        tmp.close()
        path = tmp.name
    reader = raw_reader(path, nx, ny, nz, dtype)
    inputs = [reader]
    if pad > 0:
        # The interior as its own image (extent starting at 0), computed before any timing.
        voi = vtk.vtkExtractVOI()
        voi.SetInputConnection(reader.GetOutputPort())
        voi.SetVOI(pad, nx - 1 - pad, pad, ny - 1 - pad, pad, nz - 1 - pad)
        voi.Update()
        interior = vtk.vtkImageData()
        interior.DeepCopy(voi.GetOutput())
        interior.SetExtent(0, nx - 1 - 2 * pad, 0, ny - 1 - 2 * pad, 0, nz - 1 - 2 * pad)
        producer = vtk.vtkTrivialProducer()
        producer.SetOutput(interior)
        inputs.append(producer)
    results = []
    for source in inputs:
        fe = flying_edges_filter(source, iso)
        # The minimum, like marching_cubes_bench for ours: on a shared machine it is the least disturbed run.
        results.append((timed(fe, runs, min), fe.GetOutput().GetNumberOfCells()))
    if tmp:
        os.unlink(tmp.name)
    line = f"ms={results[0][0]:.3f} triangles={results[0][1]}"
    if pad > 0:
        line += f" interior_ms={results[1][0]:.3f} interior_triangles={results[1][1]}"
    print(line + f" threads={vtk.vtkSMPTools.GetEstimatedNumberOfThreads()} "
          f"backend={vtk.vtkSMPTools.GetBackend()}")


def read_ply(path):
    reader = vtk.vtkPLYReader()
    reader.SetFileName(path)
    reader.Update()
    return reader


def windowed_sinc(path, iterations, runs):
    reader = read_ply(path)
    smoother = windowed_sinc_filter(reader, iterations)
    ms = timed(smoother, runs)
    vertices = reader.GetOutput().GetNumberOfPoints()
    print(f"ms={ms:.3f} triangles={smoother.GetOutput().GetNumberOfCells()} vertices={vertices} "
          f"vertex_iterations_per_s={vertices * iterations / (ms * 1e-3):.4g}")


def quadric_decimation(path, target, runs, out_path=None):
    reader = read_ply(path)
    faces = reader.GetOutput().GetNumberOfCells()
    decimate = vtk.vtkQuadricDecimation()
    decimate.SetInputConnection(reader.GetOutputPort())
    decimate.SetTargetReduction(1.0 - target / faces)
    ms = timed(decimate, runs)
    if out_path:
        writer = vtk.vtkPLYWriter()
        writer.SetInputConnection(decimate.GetOutputPort())
        writer.SetFileTypeToBinary()
        writer.SetFileName(out_path)
        writer.Write()
    print(f"ms={ms:.3f} triangles={decimate.GetOutput().GetNumberOfCells()} input_triangles={faces}")


def main(argv):
    mode = argv[1] if len(argv) > 1 else ""
    if mode == "flying-edges" and len(argv) in (9, 11):
        pad, threads = (int(argv[9]), int(argv[10])) if len(argv) == 11 else (0, 0)
        flying_edges(argv[2], int(argv[3]), int(argv[4]), int(argv[5]), argv[6], float(argv[7]), int(argv[8]), pad,
                     threads)
    elif mode == "windowed-sinc" and len(argv) == 5:
        windowed_sinc(argv[2], int(argv[3]), int(argv[4]))
    elif mode == "quadric-decimation" and len(argv) in (5, 6):
        quadric_decimation(argv[2], int(argv[3]), int(argv[4]), argv[5] if len(argv) == 6 else None)
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main(sys.argv)
