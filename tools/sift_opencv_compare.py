#!/usr/bin/env python3
"""Compares sillage-image's SIFT with OpenCV's on real frames (dev script, not part of the build).

Setup: python3 -m venv /tmp/sift-venv && /tmp/sift-venv/bin/pip install opencv-python-headless numpy
Build: cargo build --release -p sillage-image --example sift_dump
Run:   /tmp/sift-venv/bin/python tools/sift_opencv_compare.py [--time 15]

For each frame (grey by OpenCV, written as an 8-bit PNG that both read):
- repeatability: the fraction of OpenCV keypoints with one of ours within 1.5 px and a scale
  ratio within 1.5x, and vice versa;
- descriptors: each OpenCV keypoint is paired with the repeated keypoint of ours of closest
  orientation (kept when within 10 degrees); for those pairs, the median Euclidean distance of
  the unit-L2 descriptors and the fraction whose nearest neighbour among all of ours is the
  paired one;
- OpenCV runs with its default doubling and with `enable_precise_upscale=True` (a
  pixel-aligned doubling, like ours);
- the median position offset (ours - OpenCV): OpenCV's doubled image is shifted by 1/4 input px
  that its coordinates ignore, ours is pixel-aligned, so about -0.25 px is expected;
- timings (--time N runs, median): detect+describe, 1 and 2 threads, both libraries.
"""

import argparse
import io
import os
import subprocess
import tempfile
import time

import cv2
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.path.join(ROOT, "..", "shared", "data")
DUMP = os.path.join(ROOT, "target", "release", "examples", "sift_dump")
POS_PX, SCALE_RATIO, ANGLE_DEG = 1.5, 1.5, 10.0


def frames():
    for n in (1, 50, 100):
        path = os.path.join(DATA, "pets09_s2l1", "img1", f"{n:06d}.jpg")
        yield f"PETS09-S2L1 #{n}", cv2.imread(path, cv2.IMREAD_GRAYSCALE)
    video = cv2.VideoCapture(os.path.join(DATA, "mot15_train_gt_det", "TUD-Campus", "video", "TUD-Campus.mp4"))
    ok, bgr = video.read()
    if ok:
        yield "TUD-Campus #1", cv2.cvtColor(bgr, cv2.COLOR_BGR2GRAY)


def ours(png, permissive, repeats=0, threads=None):
    args = [DUMP, png] + (["--permissive"] if permissive else []) + (["--time", str(repeats)] if repeats else [])
    env = dict(os.environ)
    if threads:
        env["RAYON_NUM_THREADS"] = str(threads)
    run = subprocess.run(args, capture_output=True, text=True, check=True, env=env)
    table = np.loadtxt(io.StringIO(run.stdout), delimiter=",", skiprows=1, ndmin=2)
    ms = None
    for line in run.stderr.splitlines():
        if line.startswith("detect_and_describe_ms"):
            ms = float(line.split()[1])
    return table, ms


def unit(d):
    return d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-12)


def compare(grey, png, permissive, precise_upscale=False):
    thresholds = dict(contrastThreshold=0.005, edgeThreshold=7.5) if permissive else {}
    sift = cv2.SIFT_create(**thresholds, enable_precise_upscale=precise_upscale)
    kps, cv_desc = sift.detectAndCompute(grey, None)
    cv_xy = np.array([k.pt for k in kps])
    cv_sigma = np.array([k.size / 2 for k in kps])
    cv_angle = np.array([k.angle for k in kps])
    table, _ = ours(png, permissive)
    xy, sigma, angle = table[:, 0:2], table[:, 2], np.degrees(table[:, 3])
    desc = unit(table[:, 8:])
    cv_desc = unit(cv_desc.astype(np.float64))

    dist = np.linalg.norm(cv_xy[:, None, :] - xy[None, :, :], axis=2)
    ratio = np.maximum(cv_sigma[:, None] / sigma[None, :], sigma[None, :] / cv_sigma[:, None])
    close = (dist <= POS_PX) & (ratio <= SCALE_RATIO)
    cv_repeat = close.any(axis=1).mean()
    our_repeat = close.any(axis=0).mean()

    gap = np.abs((cv_angle[:, None] - angle[None, :] + 180.0) % 360.0 - 180.0)
    gap = np.where(close, gap, np.inf)
    pair = gap.argmin(axis=1)
    paired = np.isfinite(gap[np.arange(len(kps)), pair]) & (gap[np.arange(len(kps)), pair] <= ANGLE_DEG)
    rows = np.nonzero(paired)[0]
    d_pair = np.linalg.norm(cv_desc[rows] - desc[pair[rows]], axis=1)
    # Unit vectors: the nearest neighbour has the largest dot product.
    nn_ok = ((cv_desc[rows] @ desc.T).argmax(axis=1) == pair[rows]).mean()
    offset = np.median(xy[pair[rows]] - cv_xy[rows], axis=0)
    return dict(cv=len(kps), ours=len(xy), cv_repeat=cv_repeat, our_repeat=our_repeat,
                paired=len(rows), median_d=np.median(d_pair), nn=nn_ok, offset=offset)


def time_opencv(grey, threads, repeats):
    cv2.setNumThreads(threads)
    sift = cv2.SIFT_create()
    sift.detectAndCompute(grey, None)
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        sift.detectAndCompute(grey, None)
        times.append(time.perf_counter() - start)
    return 1e3 * float(np.median(times))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--time", type=int, default=0, help="timing runs per configuration")
    args = parser.parse_args()
    print(f"OpenCV {cv2.__version__}")
    print("| frame | params | OpenCV upscale | OpenCV kp | ours kp | OpenCV kp repeated | ours repeated | pairs | median desc. dist. | NN = pair | offset x, y px |")
    print("|---|---|---|---:|---:|---:|---:|---:|---:|---:|---|")
    with tempfile.TemporaryDirectory(prefix="sift-compare-") as tmp:
        first = None
        for name, grey in frames():
            png = os.path.join(tmp, "frame.png")
            cv2.imwrite(png, grey)
            if first is None:
                first = (grey.copy(), os.path.join(tmp, "first.png"))
                cv2.imwrite(first[1], grey)
            for permissive, precise in ((False, False), (False, True), (True, False), (True, True)):
                r = compare(grey, png, permissive, precise)
                print(f"| {name} | {'permissive' if permissive else 'default'} | "
                      f"{'precise' if precise else 'default'} | {r['cv']} | {r['ours']} | "
                      f"{100 * r['cv_repeat']:.1f} % | {100 * r['our_repeat']:.1f} % | {r['paired']} | "
                      f"{r['median_d']:.3f} | {100 * r['nn']:.1f} % | {r['offset'][0]:+.2f}, {r['offset'][1]:+.2f} |")
        if args.time:
            grey, png = first
            print(f"\n{grey.shape[1]}x{grey.shape[0]} detect + describe, median of {args.time} (ms)")
            print("| threads | OpenCV | sillage | ratio |")
            print("|---:|---:|---:|---:|")
            for threads in (1, 2):
                cv_ms = time_opencv(grey, threads, args.time)
                _, our_ms = ours(png, False, args.time, threads)
                print(f"| {threads} | {cv_ms:.1f} | {our_ms:.1f} | {our_ms / cv_ms:.2f} |")


if __name__ == "__main__":
    main()
