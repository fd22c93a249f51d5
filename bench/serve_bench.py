#!/usr/bin/env python3
"""raysift serve under a scripted drag (issue 18 benchmark): a 10-s orbit of the bundled engine CT at 960x600, camera
messages as the page sends them (one in flight; --pacing 60hz: a raw 60 Hz mouse stream), at target rates of 5, 10
and 20 fps. Per rate: the server's frame render time (p50/p95, the budgeted quantity), render+encode+send (p50/p95,
from --stats), the achieved rate of frames that reflect a drag camera, the latency from every camera message to the
first frame arriving that reflects it or a later one (and of the frames' own messages), and the mean SSIM_object of the
received frames against the full render of the same cameras. The drag starts once the viewer's feature geometry is
built (features_ready). The full renders are of a subset of the frames
(--compare evenly spaced frames per rate) through raysift.Renderer, the CLI's code path (apps/raysift/render_session),
in the same run, so their time is the reference of the ratio printed.

    PYTHONPATH=build/python /usr/bin/python3 bench/serve_bench.py --exe build/raysift [--format jpeg]
"""
import argparse
import json
import math
import os
import re
import statistics
import subprocess
import tempfile
import threading
import time

import numpy as np
import OpenImageIO as oiio
import websocket

import raysift

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--exe", default=os.path.join(ROOT, "build", "raysift"))
    p.add_argument("--scene", default=os.path.join(ROOT, "datasets", "engine_ct_scene.json"))
    p.add_argument("--rates", type=float, nargs="+", default=[5, 10, 20])
    p.add_argument("--seconds", type=float, default=10.0)
    p.add_argument("--width", type=int, default=960)
    p.add_argument("--height", type=int, default=600)
    p.add_argument("--format", choices=["png", "jpeg"], default="png")
    p.add_argument("--compare", type=int, default=12, help="frames per rate compared with a full render")
    p.add_argument("--pacing", choices=["flow", "60hz"], default="flow",
                   help="flow: the next camera message once a frame header reflects the last one and a frame period "
                        "has passed since it was sent (as the page does); 60hz: a message every 1/60 s whatever the "
                        "frames (a raw mouse stream)")
    p.add_argument("--json", default="", help="also write the results here")
    return p.parse_args()


def start_server(exe, scene, fps, stats_path):
    proc = subprocess.Popen([exe, "serve", "--scene", scene, "--port", "0", "--target-fps", str(fps),
                             "--stats", stats_path], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = proc.stdout.readline()
    m = re.search(r"http://127\.0\.0\.1:(\d+)/", line)
    if not m:
        proc.kill()
        raise SystemExit("serve_bench: the server printed no URL: " + line + proc.stderr.read())
    return proc, int(m.group(1))


def orbit_camera(hello_camera, t, seconds, width, height):
    """One turn about the default view's up axis through the target, at its distance, in `seconds` (Rodrigues'
    rotation of the eye; at t = 0 the default view)."""
    eye, target = np.array(hello_camera["eye"], float), np.array(hello_camera["target"], float)
    axis = np.array(hello_camera["up"], float)
    axis /= np.linalg.norm(axis)
    angle = 2 * math.pi * t / seconds
    v = eye - target
    rotated = v * math.cos(angle) + np.cross(axis, v) * math.sin(angle) + axis * np.dot(axis, v) * (1 - math.cos(angle))
    return {"eye": (target + rotated).tolist(), "target": target.tolist(), "up": hello_camera["up"],
            "fov_y_deg": hello_camera["fov_y_deg"], "width": width, "height": height}


def receive(ws, frames, stop, answered):
    """Frames (arrival time, header, image bytes) until `stop` is set and the socket times out; answered(camera_seq)
    at each frame header."""
    header = None
    while not stop.is_set():  # refinement frames may keep coming long after the drag
        try:
            m = ws.recv()
        except websocket.WebSocketTimeoutException:
            continue
        except websocket.WebSocketConnectionClosedException:
            return
        if isinstance(m, bytes):
            if header is not None:
                frames.append((time.perf_counter(), header, m))
            header = None
            continue
        j = json.loads(m)
        if j.get("type") == "error":  # a camera the server rejects would silently leave a gap in the drag
            raise SystemExit("serve_bench: the server answered: " + j.get("message", ""))
        header = j if j.get("type") == "frame" else None
        if header is not None and header.get("camera_seq") is not None:
            answered(header["camera_seq"])


def drag(port, args, fps):
    """One orbit: returns the camera messages sent {seq: (time, camera)} and the frames received."""
    ws = websocket.create_connection(f"ws://127.0.0.1:{port}/ws", timeout=120)
    hello = json.loads(ws.recv())
    ws.send(json.dumps({"type": "settings", "format": args.format}))
    # The drag starts once the feature geometry is built, as after a user's first look; its build would otherwise
    # share the two cores with the first seconds of the orbit.
    built = time.perf_counter()
    while not (isinstance(m := ws.recv(), str) and json.loads(m).get("type") == "features_ready"):
        pass
    features_ms = (time.perf_counter() - built) * 1000
    ws.settimeout(0.5)
    frames, sent, stop = [], {}, threading.Event()
    reflected = {"seq": 0}
    answer = threading.Condition()

    def answered(camera_seq):
        with answer:
            reflected["seq"] = max(reflected["seq"], camera_seq)
            answer.notify()

    receiver = threading.Thread(target=receive, args=(ws, frames, stop, answered))
    receiver.start()
    start = time.perf_counter()
    seq = 0
    while (now := time.perf_counter()) - start < args.seconds:
        seq += 1
        camera = orbit_camera(hello["camera"], now - start, args.seconds, args.width, args.height)
        sent[seq] = (time.perf_counter(), camera)
        ws.send(json.dumps(dict(camera, type="camera", seq=seq)))
        if args.pacing == "flow":  # as the page: one message in flight (unless unanswered for 1 s), one per period
            with answer:
                answer.wait_for(lambda: reflected["seq"] >= seq, timeout=1.0)
            time.sleep(max(0.0, sent[seq][0] + 1.0 / fps - time.perf_counter()))
        else:
            time.sleep(max(0.0, start + seq / 60.0 - time.perf_counter()))
    drag_end = time.perf_counter()
    time.sleep(1.0)  # the last frames of the drag arrive
    stop.set()
    receiver.join()
    ws.close()
    return sent, frames, drag_end, features_ms


def decode(image_bytes, path):
    with open(path, "wb") as f:
        f.write(image_bytes)
    pixels = oiio.ImageInput.open(path).read_image("float")[:, :, :3]  # the sRGB values the file stores
    return np.where(pixels <= 0.04045, pixels / 12.92, ((pixels + 0.055) / 1.055) ** 2.4)


def quantised(full):
    """The reference as an 8-bit sRGB frame holds it: the comparison then measures sampling, not quantisation."""
    c = np.clip(full[:, :, :3], 0, 1)
    s = np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1 / 2.4) - 0.055)
    s = np.round(s * 255) / 255
    return np.where(s <= 0.04045, s / 12.92, ((s + 0.055) / 1.055) ** 2.4)


def percentile(values, p):
    """Nearest rank, as the server's --stats."""
    v = sorted(values)
    return v[max(1, math.ceil(p * len(v))) - 1] if v else float("nan")


def evaluate(renderer, sent, frames, drag_end, args, tmp):
    in_drag = [(t, h, img) for t, h, img in frames if h["camera_seq"] is not None and t <= drag_end + 1e-3]
    latency, reflected = {}, {}  # every message -> the first frame reflecting it or a later one; the frames' own
    waiting = sorted(sent)
    for t, h, _ in in_drag:
        reflected.setdefault(h["camera_seq"], (t - sent[h["camera_seq"]][0]) * 1000)
        while waiting and waiting[0] <= h["camera_seq"]:
            latency[waiting[0]] = (t - sent[waiting[0]][0]) * 1000
            waiting.pop(0)
    step = max(1, len(in_drag) // args.compare)
    ssim, full_ms = [], []
    for t, h, img in in_drag[::step][:args.compare]:
        camera = raysift.Camera(**sent[h["camera_seq"]][1])
        started = time.perf_counter()
        full, _ = renderer.render(camera)
        full_ms.append((time.perf_counter() - started) * 1000)
        test = np.dstack([decode(img, os.path.join(tmp, "frame")), full[:, :, 3]]).astype(np.float32)
        reference = np.dstack([quantised(full), full[:, :, 3]]).astype(np.float32)
        ssim.append(raysift.compare(reference, test)["ssim_object"])
    ms = [h["ms"] for _, h, _ in in_drag]
    arrivals = [t for t, _, _ in in_drag]
    return {"frames": len(in_drag), "achieved_fps": len(in_drag) / args.seconds,
            "render_ms_p50": percentile(ms, 0.5), "render_ms_p95": percentile(ms, 0.95),
            "interval_ms_p50": percentile([1000 * (b - a) for a, b in zip(arrivals, arrivals[1:])], 0.5),
            "latency_ms_p50": percentile(list(latency.values()), 0.5),
            "latency_ms_p95": percentile(list(latency.values()), 0.95), "messages": len(sent),
            "reflected_latency_ms_p95": percentile(list(reflected.values()), 0.95),
            "ray_fraction_mean": statistics.mean(h["rays_traced"] / h["full_rays"] for _, h, _ in in_drag),
            "budget_ms_mean": statistics.mean(h["budget_ms"] for _, h, _ in in_drag),
            "ssim_object_mean": statistics.mean(ssim), "compared": len(ssim),
            "full_render_ms_p50": percentile(full_ms, 0.5)}


def main():
    args = parse_args()
    os.environ["NO_PROXY"] = os.environ["no_proxy"] = "127.0.0.1"  # the server is local, whatever proxy is set
    scene = json.load(open(args.scene))
    base = os.path.dirname(os.path.abspath(args.scene))
    renderer = raysift.Renderer(raysift.Volume.load(os.path.join(base, scene["volume"])),
                                raysift.TransferFunction.load(os.path.join(base, scene["transfer_function"])))
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for fps in args.rates:
            stats_path = os.path.join(tmp, f"stats{fps}.json")
            proc, port = start_server(args.exe, args.scene, fps, stats_path)
            load = os.getloadavg()[0]
            try:
                sent, frames, drag_end, features_ms = drag(port, args, fps)
            finally:
                proc.terminate()
                proc.wait(timeout=30)
            r = evaluate(renderer, sent, frames, drag_end, args, tmp)
            server = json.load(open(stats_path))["frame_ms"].get("prioritized", {})
            r.update(features_ready_ms=features_ms, total_ms_p50=server.get("total_p50"), total_ms_p95=server.get("total_p95"), load=load,
                     target_ms=1000 / fps, frame_over_full=r["render_ms_p50"] / r["full_render_ms_p50"])
            results[fps] = r
            print(f"target {fps:g} fps ({args.format}, {args.pacing}, load {load:.1f}): achieved {r['achieved_fps']:.2f} fps, "
                  f"render p50/p95 {r['render_ms_p50']:.1f}/{r['render_ms_p95']:.1f} ms (budget mean "
                  f"{r['budget_ms_mean']:.1f}), render+encode+send p50/p95 {r['total_ms_p50']:.1f}/"
                  f"{r['total_ms_p95']:.1f} ms, latency p50/p95 {r['latency_ms_p50']:.1f}/{r['latency_ms_p95']:.1f} ms over "
                  f"{r['messages']} messages ({r['latency_ms_p95'] * fps / 1000:.2f}x the period; reflected p95 "
                  f"{r['reflected_latency_ms_p95']:.1f})"
                  f", rays {100 * r['ray_fraction_mean']:.1f}%, SSIM_object {r['ssim_object_mean']:.4f} over "
                  f"{r['compared']} frames; full render p50 {r['full_render_ms_p50']:.1f} ms (frame/full "
                  f"{r['frame_over_full']:.2f}); features ready after {features_ms:.0f} ms", flush=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=2)


if __name__ == "__main__":
    main()
