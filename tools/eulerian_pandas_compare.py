#!/usr/bin/env python3
"""Cross-check and time `sillage eulerian` against pandas on the same track table.

Usage: tools/eulerian_pandas_compare.py TRACKS.csv [--bin 16] [--sillage target/release/sillage]

pandas reads the whole table, bins it with a groupby and computes the per-bin mean velocity
and population (co)variances; sillage streams the rows. Prints both times, both peak memories
(each in its own process) and the largest relative difference of u, v, uu, vv, uv.
"""
import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time


def pandas_stats(path, bin_size):
    import numpy as np
    import pandas as pd

    df = pd.read_csv(path, usecols=["x", "y", "vx", "vy"])
    df = df.dropna(subset=["vx", "vy"])
    df["column"] = np.floor(df["x"] / bin_size).astype("int64")
    df["row"] = np.floor(df["y"] / bin_size).astype("int64")
    df["uv"] = df["vx"] * df["vy"]
    g = df.groupby(["column", "row"])
    out = g.agg(u=("vx", "mean"), v=("vy", "mean"), uu=("vx", lambda s: s.var(ddof=0)),
                vv=("vy", lambda s: s.var(ddof=0)), m_uv=("uv", "mean"))
    out["uv"] = out["m_uv"] - out["u"] * out["v"]
    return out.drop(columns="m_uv")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("tracks")
    parser.add_argument("--bin", type=float, default=16.0)
    parser.add_argument("--sillage", default="target/release/sillage")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        start = time.perf_counter()
        stats = pandas_stats(args.tracks, args.bin)
        seconds = time.perf_counter() - start
        stats.to_csv(sys.stdout)
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        print(json.dumps({"seconds": seconds, "peak_mib": peak}), file=sys.stderr)
        return
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "stats.csv")
        start = time.perf_counter()
        child = subprocess.Popen([args.sillage, "eulerian", args.tracks, "--bin", str(args.bin),
                                  "--out", out], stderr=subprocess.DEVNULL)
        _, status, usage = os.wait4(child.pid, 0)
        sillage_s = time.perf_counter() - start
        if status != 0:
            sys.exit(f"sillage eulerian failed (status {status})")
        # An upper bound: the child's peak includes this (small, pandas-free) interpreter
        # it was forked from.
        sillage_peak = usage.ru_maxrss / 1024
        import pandas as pd

        ours = pd.read_csv(out).set_index(["column", "row"])
        child = subprocess.run([sys.executable, __file__, args.tracks, "--bin", str(args.bin),
                                "--child"], check=True, capture_output=True, text=True)
        theirs = pd.read_csv(__import__("io").StringIO(child.stdout)).set_index(["column", "row"])
        timing = json.loads(child.stderr.strip().splitlines()[-1])
    theirs = theirs.add_suffix("_pd")
    joined = ours.join(theirs, how="inner")
    worst = 0.0
    for name in ["u", "v", "uu", "vv", "uv"]:
        scale = (joined[name + "_pd"].abs() + 1e-300)
        if name == "uv":
            scale = (joined["uu_pd"] * joined["vv_pd"]) ** 0.5
        worst = max(worst, float(((joined[name] - joined[name + "_pd"]).abs() / scale).max()))
    print(f"bins compared: {len(joined)} (sillage {len(ours)}, pandas {len(theirs)})")
    print(f"largest relative difference of u, v, uu, vv, uv: {worst:.2e}")
    print(f"sillage eulerian: {sillage_s:.2f} s (process, wall), peak RSS {sillage_peak:.0f} MiB")
    print(f"pandas groupby:   {timing['seconds']:.2f} s (read + groupby), peak RSS "
          f"{timing['peak_mib']:.0f} MiB")


if __name__ == "__main__":
    main()
