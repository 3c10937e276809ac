#!/usr/bin/env python3
"""Leave-one-sequence-out choice of the IMM-PF's detections-only life cycle.

Runs `sillage bench immpf --detections-only` for every combination of the life-cycle
switches and smoothings below on every sequence given, then, for each sequence in turn, picks the
combination with the best mean (MOTA + IDF1) / 2 on the *other* sequences and reports what
that pick scores on the held-out one, beside SORT and ByteTrack in the same harness: figures
that the choice each row reports never saw (docs/immpf.md quotes them). `--grid` replaces
the values tried for a switch.

    python3 tools/immpf_loso.py --sillage target/release/sillage \
        ../shared/data/mot15_train_gt_det/*/ ../shared/data/pets09_s2l1

Standard library only; the binary does the tracking and the scoring.
"""

import argparse
import itertools
import json
import subprocess
import sys

SWITCHES = {
    "detection.lost_frames": [1, 5, 30],
    "detection.min_hits": [3, 4, 5],
    "detection.report_first_hits": ["true", "false"],
    "detection.velocity_proposal": ["true", "false"],
    "detection.size_smoothing": [0.3, 0.7],
    "detection.high_score": [0.5, 0.7, 0.9],
}


def bench(sillage, sequences, settings, models, runs):
    """{sequence: {label: (mota, idf1)}} for one combination (label "IMM-PF"), plus the
    baselines' rows under their own labels."""
    command = [sillage, "bench", "immpf", "--detections-only", "--json",
               "--models", models, "--runs", str(runs)]
    for key, value in settings:
        command += ["--set", f"tracker.{key}={value}"]
    done = subprocess.run(command + sequences, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"{' '.join(command)} failed:\n{done.stderr}")
    scores = {}
    for row in json.loads(done.stdout):
        label = row["models"] if row["models"] in ("SORT", "ByteTrack") else "IMM-PF"
        median = row["median"]
        scores.setdefault(row["sequence"], {})[label] = (median["mota"], median["idf1"])
    return scores


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sequences", nargs="+", help="MOTChallenge sequence folders")
    parser.add_argument("--sillage", default="target/release/sillage")
    parser.add_argument("--models", default="CV_CA")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--grid", action="append", default=[], metavar="KEY=V1,V2",
                        help="replace the grid of the switches named (repeatable), e.g. "
                             "detection.min_hits=5,6,7; KEY=V alone fixes a switch")
    args = parser.parse_args()
    grid = dict(SWITCHES)
    for item in args.grid:
        key, _, values = item.partition("=")
        if not values:
            sys.exit(f"--grid {item}: write KEY=V1,V2")
        grid[key] = values.split(",")
    sequences = [s for s in args.sequences if not s.endswith(".md")]

    combos = [tuple(zip(grid, values)) for values in itertools.product(*grid.values())]
    results = {}
    for combo in combos:
        results[combo] = bench(args.sillage, sequences, combo, args.models, args.runs)
        print("measured", ", ".join(f"{k}={v}" for k, v in combo), file=sys.stderr)
    names = sorted(next(iter(results.values())))

    def objective(combo, names_in):
        pairs = [results[combo][n]["IMM-PF"] for n in names_in]
        return sum((m + i) / 2 for m, i in pairs) / len(pairs)

    print("| held out | chosen on the others | IMM-PF MOTA / IDF1 | SORT | ByteTrack |")
    print("|---|---|---|---|---|")
    picks = {}
    for held in names:
        others = [n for n in names if n != held]
        best = max(combos, key=lambda c: objective(c, others))
        picks[best] = picks.get(best, 0) + 1
        row = results[best][held]
        label = ", ".join(f"{k.split('.')[1]}={v}" for k, v in best)
        cells = [f"{row[k][0]:.1f} / {row[k][1]:.1f}" for k in ("IMM-PF", "SORT", "ByteTrack")]
        print(f"| {held} | {label} | " + " | ".join(cells) + " |")
    print()
    for combo, count in sorted(picks.items(), key=lambda kv: -kv[1]):
        print(f"chosen {count}×:", ", ".join(f"{k}={v}" for k, v in combo))


if __name__ == "__main__":
    main()
