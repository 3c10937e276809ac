"""Time windows on Dask: one sequence tracked by ``sillage.dask.track`` on a LocalCluster of 1
and of 2 single-threaded workers, and by the single run, in one run of this script.

    python benches/python/bench_dask_windows.py FRAMES_FOLDER [--window 100] [--overlap 16]
                                                [--parquet] [--dask-defaults]

FRAMES_FOLDER is a sequence on disk, e.g. 400 frames of the vortex on 2048 x 2048 px:
``sillage synth vortex --out /tmp/v2048 --frames 400 --particles 25000 --width 2048
--height 2048 --seed 3``. Prints the wall times, the speed-up of 2 workers over 1, the
windowed runs against the single run (all cores, one process), and how far the stitched
trajectories agree with the single run's (points present, seam-crossing identities kept).
With ``--parquet`` the windowed runs write partitioned Parquet on the workers (``out=``)
instead of returning one DataFrame to this process. The workers start with
``sillage.dask.FAST_WORKERS`` unless ``--dask-defaults`` is given.
"""

import argparse
import glob
import json
import os
import platform
import tempfile
import time

import dask
import pandas as pd
from distributed import Client, LocalCluster

import sillage


def timed(function):
    start = time.perf_counter()
    result = function()
    return time.perf_counter() - start, result


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("frames")
    parser.add_argument("--window", type=int, default=100)
    parser.add_argument("--overlap", type=int, default=16)
    parser.add_argument("--parquet", action="store_true",
                        help="write partitioned Parquet on the workers")
    parser.add_argument("--dask-defaults", action="store_true",
                        help="start the workers with Dask's defaults, not FAST_WORKERS")
    args = parser.parse_args()
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"sillage {sillage.__version__}, {args.frames}, window {args.window}, "
          f"overlap {args.overlap}, {'Parquet parts' if args.parquet else 'one DataFrame'}, "
          f"{'Dask defaults' if args.dask_defaults else 'FAST_WORKERS'}")

    single_s, single = timed(lambda: sillage.track(args.frames))
    print(f"single run (one process, all cores): {single_s:.2f} s, {len(single)} points")
    runs = {}
    for workers in (1, 2):
        with dask.config.set({} if args.dask_defaults else sillage.dask.FAST_WORKERS), \
                LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                             dashboard_address=":0") as cluster, Client(cluster) as client:
            client.wait_for_workers(workers)
            with tempfile.TemporaryDirectory() as out:
                seconds, _ = timed(lambda: sillage.dask.track(
                    args.frames, window=args.window, overlap=args.overlap, client=client,
                    out=out if args.parquet else None))
                tracks = _
                if args.parquet:
                    tracks = pd.concat([pd.read_parquet(part) for part in
                                        sorted(glob.glob(os.path.join(out, "part-*.parquet")))],
                                       ignore_index=True)
                    with open(os.path.join(out, "seams.json"), encoding="utf-8") as seams:
                        tracks.attrs["seams"] = json.load(seams)
        runs[workers] = (seconds, tracks)
        print(f"dask, {workers} worker(s) x 1 thread: {seconds:.2f} s, {len(tracks)} points")
    (one_s, one), (two_s, two) = runs[1], runs[2]
    pd.testing.assert_frame_equal(one, two)
    print(f"speed-up of 2 workers over 1: {one_s / two_s:.2f}x; "
          f"2 workers against the single run: {single_s / two_s:.2f}x")
    agreed = sillage.dask.agreement(single, two)
    print(f"against the single run: {100 * agreed['points']:.4f} % of its points present, "
          f"{100 * agreed['identities']:.3f} % of {agreed['crossing']} seam-crossing "
          f"trajectories keep one identity")


if __name__ == "__main__":
    main()
