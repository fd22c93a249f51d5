#!/usr/bin/python3
"""Reference timing for bench/raycast_bench: VTK's CPU ray caster (vtkFixedPointVolumeRayCastMapper).

Renders a headerless raw volume (x fastest, voxel (0,0,0) at the world origin, spacing 1, like our
VDB import) with a raysift transfer function and camera, shading off, fixed sample distance, and
prints the median render time of several frames excluding window creation and the first frame.
Bench-only: needs Debian's python3-vtk9 and an X display (run under xvfb-run).

Usage: xvfb-run -a /usr/bin/python3 bench/vtk_raycast.py --raw engine.raw.gz --dims 256,256,128
         --tf tf.json --camera camera.json --width 1440 --height 900 --step 1 --threads 2 [--out vtk.png]
"""
import argparse
import gzip
import json
import os
import statistics
import tempfile
import time

import vtk

VTK_TYPES = {"uint8": "SetDataScalarTypeToUnsignedChar", "uint16": "SetDataScalarTypeToUnsignedShort",
             "float32": "SetDataScalarTypeToFloat"}


def load_points(path):
    """Our TF in plain form: [[x, r, g, b, a], ...]; ParaView presets are converted by raysift first."""
    with open(path) as f:
        j = json.load(f)
    if isinstance(j, dict) and "points" in j:
        return j["points"]
    entry = j[0]
    rgb, op = entry["RGBPoints"], entry.get("Points")
    pts = {}
    for i in range(0, len(rgb), 4):
        pts.setdefault(rgb[i], [None, None])[0] = rgb[i + 1:i + 4]
    if op:
        for i in range(0, len(op), 4):
            pts.setdefault(op[i], [None, None])[1] = op[i + 1]
    xs = sorted(pts)

    def interp(x, key):
        known = [(k, pts[k][key]) for k in xs if pts[k][key] is not None]
        if x <= known[0][0]:
            return known[0][1]
        for (x0, v0), (x1, v1) in zip(known, known[1:]):
            if x <= x1:
                t = (x - x0) / (x1 - x0)
                if isinstance(v0, list):
                    return [a + (b - a) * t for a, b in zip(v0, v1)]
                return v0 + (v1 - v0) * t
        return known[-1][1]
    return [[x] + list(interp(x, 0)) + [interp(x, 1) if op else 1.0] for x in xs]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--raw", required=True)
    ap.add_argument("--dims", required=True)
    ap.add_argument("--dtype", default="uint8", choices=sorted(VTK_TYPES))
    ap.add_argument("--tf", required=True)
    ap.add_argument("--camera", required=True, help="raysift camera JSON (eye, target, up, fov_y_deg)")
    ap.add_argument("--width", type=int, default=1440)
    ap.add_argument("--height", type=int, default=900)
    ap.add_argument("--step", type=float, default=1.0)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--frames", type=int, default=5)
    ap.add_argument("--background", default="0,0,0")
    ap.add_argument("--out", default="")
    a = ap.parse_args()

    dims = [int(v) for v in a.dims.split(",")]
    opener = gzip.open if a.raw.endswith(".gz") else open
    with opener(a.raw, "rb") as f:
        data = f.read()
    tmp = tempfile.NamedTemporaryFile(suffix=".raw", delete=False)
    tmp.write(data)
    tmp.close()
    reader = vtk.vtkImageReader2()  # the data in its native type (VTK's fast path for uint8)
    reader.SetFileName(tmp.name)
    getattr(reader, VTK_TYPES[a.dtype])()
    reader.SetDataByteOrderToLittleEndian()
    reader.SetFileDimensionality(3)
    reader.SetDataExtent(0, dims[0] - 1, 0, dims[1] - 1, 0, dims[2] - 1)
    reader.SetDataSpacing(1, 1, 1)
    reader.SetDataOrigin(0, 0, 0)
    reader.FileLowerLeftOn()  # rows are stored y = 0 first, like our import (the default flips y)
    reader.Update()
    os.unlink(tmp.name)
    image = reader.GetOutput()

    color = vtk.vtkColorTransferFunction()
    opacity = vtk.vtkPiecewiseFunction()
    for x, r, g, b, o in load_points(a.tf):
        color.AddRGBPoint(x, r, g, b)
        opacity.AddPoint(x, o)
    prop = vtk.vtkVolumeProperty()
    prop.SetColor(color)
    prop.SetScalarOpacity(opacity)
    prop.SetScalarOpacityUnitDistance(1.0)  # our convention: TF opacity per voxel length
    prop.SetInterpolationTypeToLinear()
    prop.ShadeOff()

    mapper = vtk.vtkFixedPointVolumeRayCastMapper()
    mapper.SetInputData(image)
    mapper.AutoAdjustSampleDistancesOff()
    mapper.LockSampleDistanceToInputSpacingOff()
    mapper.SetSampleDistance(a.step)
    mapper.SetInteractiveSampleDistance(a.step)
    mapper.SetImageSampleDistance(1.0)
    mapper.SetNumberOfThreads(a.threads)

    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    ren = vtk.vtkRenderer()
    ren.AddVolume(volume)
    ren.SetBackground(*[float(c) for c in a.background.split(",")])
    win = vtk.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.AddRenderer(ren)
    win.SetSize(a.width, a.height)

    with open(a.camera) as f:
        cam_j = json.load(f)
    cam = ren.GetActiveCamera()
    cam.SetPosition(*cam_j["eye"])
    cam.SetFocalPoint(*cam_j["target"])
    cam.SetViewUp(*cam_j.get("up", [0, 1, 0]))
    cam.SetViewAngle(cam_j.get("fov_y_deg", 45.0))
    ren.ResetCameraClippingRange()

    win.Render()  # window creation, first-frame setup (min-max volume for space leaping)
    times = []
    for _ in range(a.frames):
        t0 = time.perf_counter()
        win.Render()
        times.append((time.perf_counter() - t0) * 1000.0)
    if a.out:
        grab = vtk.vtkWindowToImageFilter()
        grab.SetInput(win)
        grab.Update()
        writer = vtk.vtkPNGWriter()
        writer.SetFileName(a.out)
        writer.SetInputConnection(grab.GetOutputPort())
        writer.Write()
    print(f"vtk_render_ms {statistics.median(times):.3f}")
    print(f"vtk_render_ms_all {' '.join(f'{t:.1f}' for t in times)}")


if __name__ == "__main__":
    main()
