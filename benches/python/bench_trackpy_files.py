"""sillage's whole run against trackpy's locate + link, on the same image files.

    python benches/python/bench_trackpy_files.py FRAMES_DIR SILLAGE_BINARY \
        [--frames 12] [--diameter 7] [--search-range 10] [--adaptive-stop 2]

trackpy (with numba when it is installed: ``engine="auto"`` and ``link_strategy="auto"``
pick it) locates every frame with ``trackpy.batch(frames, diameter)`` and links with
``trackpy.link(features, search_range, memory=0, adaptive_stop, adaptive_step=0.95)`` (at
this density a fixed search range makes subnetworks too large for trackpy, which refuses
them; the adaptive search is trackpy's documented remedy); its time excludes reading the
files and numba's compilation (both stages run once on two frames first).
sillage runs ``sillage ptv FRAMES --out run_track.txt`` on a folder holding the same
frames: its time is the whole process (reading, detection, tracking, writing the file).
Prints both per frame and their ratio. Set ``OPENBLAS_NUM_THREADS=1``: OpenBLAS's idle
threads, loaded with trackpy's scipy, otherwise spin on small machines.
"""

import argparse
import glob
import os
import platform
import subprocess
import tempfile
import time

import numpy as np
import trackpy
from PIL import Image


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("frames_dir", help="folder of 8-bit TIFF frames (*.tif)")
    parser.add_argument("sillage", help="path of the sillage binary (release build)")
    parser.add_argument("--frames", type=int, default=12)
    parser.add_argument("--diameter", type=int, default=7, help="trackpy's feature diameter, odd px")
    parser.add_argument("--search-range", type=float, default=10.0, help="trackpy.link's px")
    parser.add_argument("--adaptive-stop", type=float, default=2.0, help="trackpy.link's px")
    args = parser.parse_args()

    paths = sorted(glob.glob(os.path.join(args.frames_dir, "*.tif")))[: args.frames]
    if len(paths) < 3:
        raise SystemExit(f"{args.frames_dir}: fewer than 3 *.tif frames")
    frames = [np.asarray(Image.open(p)) for p in paths]
    n = len(frames)

    try:
        import numba

        engine = f"numba {numba.__version__}"
    except ImportError:
        engine = "no numba (pure Python engines)"
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} CPUs; "
          f"trackpy {trackpy.__version__}, {engine}; {n} frames of "
          f"{frames[0].shape[1]}x{frames[0].shape[0]}")

    trackpy.quiet()
    # numba compiles on first use: warm both stages up on two frames, untimed.
    warm = trackpy.batch(frames[:2], args.diameter, processes=1)
    trackpy.link(warm, args.search_range, memory=0, adaptive_stop=args.adaptive_stop,
                 adaptive_step=0.95)
    start = time.perf_counter()
    features = trackpy.batch(frames, args.diameter, processes=1)
    located = time.perf_counter()
    trackpy.link(features, args.search_range, memory=0, adaptive_stop=args.adaptive_stop,
                 adaptive_step=0.95)
    linked = time.perf_counter()
    locate_s, link_s = located - start, linked - located
    print(f"trackpy: locate {1e3 * locate_s / n:.1f} ms/frame "
          f"({len(features) / n:.0f} features/frame), link {1e3 * link_s / n:.1f} ms/frame")

    with tempfile.TemporaryDirectory() as tmp:
        frames_dir = os.path.join(tmp, "frames")
        os.mkdir(frames_dir)
        for p in paths:
            os.symlink(os.path.abspath(p), os.path.join(frames_dir, os.path.basename(p)))
        start = time.perf_counter()
        subprocess.run([args.sillage, "ptv", frames_dir, "--out",
                        os.path.join(tmp, "run_track.txt")], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        sillage_s = time.perf_counter() - start
    print(f"sillage ptv, whole process: {1e3 * sillage_s / n:.1f} ms/frame")
    print(f"ratio (trackpy locate + link) / sillage: {(locate_s + link_s) / sillage_s:.1f}x")


if __name__ == "__main__":
    main()
