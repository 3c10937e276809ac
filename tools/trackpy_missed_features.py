"""How faint the trackpy features that sillage's default detections miss are, on trackpy's
tutorial movie (docs/ptv.md, "How faint the missed features are").

For each of trackpy's features (`trackpy.batch(frames, 11, invert=True, minmass=20)`), the
difference of Gaussians (σ and 1.6σ) of the inverted frame at its position, in robust
deviations of that frame's response (median absolute deviation × 1.4826), at four σ; then,
for thresholds t, the share of trackpy's features that have a local maximum (3 × 3) of that
filter above t within 1.5 px — what a detector of such peaks could match at best.

    python tools/trackpy_missed_features.py [--frames 10]
"""

import argparse

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

import sillage
from trackpy_bulk_water_compare import load_frames, matched_flags, trackpy_features

SIGMAS_PX = (1.1, 1.7, 2.2, 3.0)
FAINT = 6.0


def standardised_dog(frame, sigma):
    """The frame's difference of Gaussians (dark particles positive) in robust deviations."""
    inverted = 255.0 - frame.astype(float)
    dog = ndimage.gaussian_filter(inverted, sigma) - ndimage.gaussian_filter(inverted, 1.6 * sigma)
    median = np.median(dog)
    return (dog - median) / (1.4826 * np.median(np.abs(dog - median)))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=10)
    args = parser.parse_args()
    frames = load_frames(args.frames)
    reference = trackpy_features(frames)
    features = sillage.batch(frames.astype(np.float32) / 255.0)
    found, response, nearest = [], [], []
    peak_hits = {(s, t): 0 for s in SIGMAS_PX for t in (3, 6)}
    peak_counts = dict.fromkeys(peak_hits, 0)
    for index, frame in enumerate(frames):
        ref = reference[reference.frame == index][["x", "y"]].to_numpy()
        ours = features[features.frame == index][["x", "y"]].to_numpy()
        found.append(matched_flags(ref, ours))
        nearest.append(cKDTree(ours).query(ref)[0])
        col = np.clip(np.round(ref[:, 0]).astype(int), 0, frame.shape[1] - 1)
        row = np.clip(np.round(ref[:, 1]).astype(int), 0, frame.shape[0] - 1)
        per_sigma = []
        for sigma in SIGMAS_PX:
            z = standardised_dog(frame, sigma)
            per_sigma.append(z[row, col])
            is_max = z == ndimage.maximum_filter(z, size=3)
            for t in (3, 6):
                rows, cols = np.nonzero(is_max & (z > t))
                peak_counts[sigma, t] += len(rows)
                peak_hits[sigma, t] += int((cKDTree(np.c_[cols, rows]).query(ref)[0] <= 1.5).sum())
        response.append(np.stack(per_sigma, axis=1))
    found, response, nearest = map(np.concatenate, (found, response, nearest))
    missed = ~found
    print(f"{found.mean():.1%} of trackpy's {len(found)} features found "
          f"({len(features) / len(frames):.0f} detections per frame)")
    for k, sigma in enumerate(SIGMAS_PX):
        q1, med, q3 = np.percentile(response[missed, k], [25, 50, 75])
        print(f"σ {sigma} px: missed {med:.1f} ({q1:.1f}-{q3:.1f}) deviations, "
              f"found {np.median(response[found, k]):.1f}")
    faint = response.max(axis=1) < FAINT
    strong_missed = missed & ~faint
    print(f"missed below {FAINT:g} deviations at every σ: {(missed & faint).sum()} "
          f"(found ones: {faint[found].mean():.1%}); of the {strong_missed.sum()} others, "
          f"{(strong_missed & (nearest < 3)).sum()} have a detection within 3 px")
    for (sigma, t), hits in peak_hits.items():
        print(f"σ {sigma} px, maxima above {t}: {hits / len(found):.1%} of trackpy's features "
              f"within 1.5 px ({peak_counts[sigma, t] / len(frames):.0f} maxima per frame)")


if __name__ == "__main__":
    main()
