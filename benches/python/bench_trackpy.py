"""sillage vs trackpy from Python, on the same data in the same run.

    python benches/python/bench_trackpy.py [--frames N] [--link-particles N]

1. Detection: ``sillage.batch`` vs ``trackpy.batch`` on the same frames (the synthetic vortex
   of the TracTrac paper, 1024 x 1024 px, Gaussian spots of sigma 2 px).
2. Linking: ``sillage.link`` vs ``trackpy.link(search_range, memory=0)`` on the same
   detections DataFrame: N random points per frame (default 20,000 on 2048 x 2048 px) moved
   by a smooth vortex of up to 2 px/frame. Each result is also scored: the share of links
   (same particle id in frames t and t+1) that join the same true particle.

Prints per-frame times and the speed ratios (best of --repeat runs for sillage, one run for
trackpy, which is far slower).
"""

import argparse
import platform
import time

import numpy as np
import pandas as pd
import trackpy

import sillage


def best_time(function, repeat):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return min(times), result


def vortex_points(n, frames, side, seed):
    """``n`` points per frame moved by a smooth vortex (max speed 2 px/frame), with truth."""
    rng = np.random.default_rng(seed)
    xy = rng.uniform(0, side, size=(n, 2))
    centre, radius = side / 2, side / 4
    rows = []
    for frame in range(frames):
        rows.append(pd.DataFrame({"frame": frame, "x": xy[:, 0], "y": xy[:, 1],
                                  "truth": np.arange(n)}))
        dx, dy = xy[:, 0] - centre, xy[:, 1] - centre
        r = np.hypot(dx, dy)
        speed = 2.0 * (r / radius) * np.exp(0.5 * (1 - (r / radius) ** 2))  # Lamb-Oseen-like
        xy = xy + np.stack([-dy, dx], axis=1) / np.maximum(r, 1e-9)[:, None] * speed[:, None]
    return pd.concat(rows, ignore_index=True)


def link_purity(linked):
    """Share of links (a particle in frames t and t+1) that join the same true particle."""
    ordered = linked.sort_values(["particle", "frame"])
    same = ordered.particle.to_numpy()[1:] == ordered.particle.to_numpy()[:-1]
    next_frame = np.diff(ordered.frame.to_numpy()) == 1
    links = same & next_frame
    correct = links & (ordered.truth.to_numpy()[1:] == ordered.truth.to_numpy()[:-1])
    return correct.sum() / max(links.sum(), 1), links.sum()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=5)
    parser.add_argument("--detect-particles", type=int, default=5000)
    parser.add_argument("--link-particles", type=int, default=20000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    print(f"python {platform.python_version()}, trackpy {trackpy.__version__}, "
          f"sillage {sillage.__version__}, {platform.machine()}")

    frames, _ = sillage.synth_vortex(width=1024, height=1024, n_frames=args.frames,
                                     n_particles=args.detect_particles, seed=1)
    frames16 = np.round(frames * 65535).astype(np.uint16)
    t_sillage, ours = best_time(lambda: sillage.batch(frames16, scale_px=2.0), args.repeat)
    start = time.perf_counter()
    theirs = trackpy.batch(list(frames16), 7, processes=1)
    t_trackpy = time.perf_counter() - start
    n = args.frames
    print(f"\nbatch, {n} frames 1024x1024 uint16, {args.detect_particles} spots/frame:")
    print(f"  trackpy.batch(diameter=7): {t_trackpy / n * 1e3:9.1f} ms/frame, "
          f"{len(theirs) / n:.0f} features/frame")
    print(f"  sillage.batch(scale_px=2): {t_sillage / n * 1e3:9.1f} ms/frame, "
          f"{len(ours) / n:.0f} features/frame")
    print(f"  ratio: {t_trackpy / t_sillage:.1f}x")

    points = vortex_points(args.link_particles, args.frames, 2048.0, seed=2)
    t_sillage, ours = best_time(lambda: sillage.link(points), args.repeat)
    start = time.perf_counter()
    theirs = trackpy.link(points, search_range=4, memory=0)
    t_trackpy = time.perf_counter() - start
    print(f"\nlink, {n} frames of {args.link_particles} points (2048x2048 px, <= 2 px/frame):")
    for name, t, linked in (("trackpy.link(search_range=4, memory=0)", t_trackpy, theirs),
                            ("sillage.link()", t_sillage, ours)):
        purity, links = link_purity(linked)
        print(f"  {name:40s} {t / n * 1e3:9.1f} ms/frame, {links} links, "
              f"{purity:.4f} correct")
    print(f"  ratio: {t_trackpy / t_sillage:.1f}x")


if __name__ == "__main__":
    trackpy.quiet()
    main()
