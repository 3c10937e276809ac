"""Share of trackpy's features that sillage's default detections find, on trackpy's tutorial
movie (`../shared/data/trackpy_bulk_water`, dark 1-µm spheres, no ground truth).

trackpy is run as its walkthrough does, `trackpy.batch(frames, 11, invert=True, minmass=20)`;
sillage with its defaults (size and polarity measured from the first frame) and, for
comparison, at a few detection thresholds. A trackpy feature counts as found when a sillage
detection of the same frame lies within 1.5 px (one-to-one, nearest first).

    python tools/trackpy_bulk_water_compare.py [--frames 10]
"""

import argparse
import glob
import pathlib

import numpy as np
import trackpy
from PIL import Image
from scipy.optimize import linear_sum_assignment
from scipy.spatial import cKDTree

import sillage

DATA = pathlib.Path(__file__).resolve().parents[2] / "shared" / "data" / "trackpy_bulk_water" / "frames"


def matched_flags(reference, found, radius=1.5):
    """Per `reference` point, whether it has a one-to-one partner in `found` within `radius`
    (nearest first, by the Hungarian algorithm on the distances)."""
    flags = np.zeros(len(reference), dtype=bool)
    if len(reference) == 0 or len(found) == 0:
        return flags
    tree = cKDTree(found)
    pairs = tree.query_ball_point(reference, radius)
    cost = np.full((len(reference), len(found)), 1e6)
    for i, js in enumerate(pairs):
        for j in js:
            cost[i, j] = np.hypot(*(reference[i] - found[j]))
    rows, cols = linear_sum_assignment(cost)
    flags[rows[cost[rows, cols] < radius]] = True
    return flags


def matched(reference, found, radius=1.5):
    """Number of `reference` points with a one-to-one partner in `found` within `radius`."""
    return int(matched_flags(reference, found, radius).sum())


def load_frames(count):
    """The movie's first `count` frames as one uint8 array (frames, rows, columns)."""
    files = sorted(glob.glob(str(DATA / "*.png")))[:count]
    return np.array([np.asarray(Image.open(f).convert("L")) for f in files])


def trackpy_features(frames):
    """trackpy's features as its walkthrough finds them."""
    trackpy.quiet()
    return trackpy.batch(frames, 11, invert=True, minmass=20, processes=1)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=10)
    args = parser.parse_args()
    frames = load_frames(args.frames)
    reference = trackpy_features(frames)
    settings = {"defaults": {}}
    for k in (3.0, 2.0):
        settings[f"defaults, threshold.noise.k={k:g}"] = {"threshold": {"noise": {"k": k}}}
    for name, params in settings.items():
        features = sillage.batch(frames.astype(np.float32) / 255.0, **params)
        total = found = 0
        for frame in range(len(frames)):
            ref = reference[reference.frame == frame][["x", "y"]].to_numpy()
            ours = features[features.frame == frame][["x", "y"]].to_numpy()
            total += len(ref)
            found += matched(ref, ours)
        per_frame = len(features) / len(frames)
        print(f"{name}: {100 * found / total:.1f} % of trackpy's {total} features within 1.5 px "
              f"({per_frame:.0f} detections per frame)")


if __name__ == "__main__":
    main()
