"""SORT and ByteTrack in sillage (`sillage track boxes --tracker sort|bytetrack`) against
the references on the same public detections — the authors' SORT (`sort-tracker-py`, Bewley's
`sort.py`) and `supervision` 0.30.9's `sv.ByteTrack` — all scored by `sillage eval mot`.

Usage: python tools/box_trackers_compare.py [SILLAGE_BINARY] [DATA_DIR]
Needs: pip install sort-tracker-py "supervision==0.30.9". Prints one row per sequence and
tracker: MOTA and IDF1 of the reference and of ours.
"""
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from sort_tracker import Sort

SILLAGE = sys.argv[1] if len(sys.argv) > 1 else "target/release/sillage"
DATA = Path(sys.argv[2] if len(sys.argv) > 2 else "../shared/data")


def sequences():
    for seq in sorted((DATA / "mot15_train_gt_det").iterdir()):
        if (seq / "det" / "det.txt").exists() and (seq / "gt" / "gt.txt").exists():
            yield seq
    pets = DATA / "pets09_s2l1"
    if (pets / "det" / "det.txt").exists():
        yield pets


def reference_sort(det_file: Path, out_file: Path):
    dets = np.loadtxt(det_file, delimiter=",", ndmin=2)
    tracker = Sort(max_age=1, min_hits=3, iou_threshold=0.3)
    rows = []
    for frame in range(1, int(dets[:, 0].max()) + 1):
        d = dets[dets[:, 0] == frame, 2:7].copy()
        d[:, 2:4] += d[:, 0:2]
        for row in tracker.update(d if len(d) else np.empty((0, 5))):
            (x1, y1, x2, y2), tid = row[:4], row[-1]  # this package also returns the score
            rows.append(f"{frame},{int(tid)},{x1:.2f},{y1:.2f},{x2 - x1:.2f},{y2 - y1:.2f},1,-1,-1,-1")
    out_file.write_text("\n".join(rows) + "\n")


def reference_bytetrack(det_file: Path, out_file: Path):
    import supervision as sv

    dets = np.loadtxt(det_file, delimiter=",", ndmin=2)
    tracker = sv.ByteTrack()
    rows = []
    for frame in range(1, int(dets[:, 0].max()) + 1):
        d = dets[dets[:, 0] == frame]
        xyxy = d[:, 2:6].copy()
        xyxy[:, 2:4] += xyxy[:, 0:2]
        tracked = tracker.update_with_detections(
            sv.Detections(xyxy=xyxy.reshape(-1, 4), confidence=d[:, 6].copy()))
        for (x1, y1, x2, y2), tid in zip(tracked.xyxy, tracked.tracker_id):
            rows.append(f"{frame},{int(tid)},{x1:.2f},{y1:.2f},{x2 - x1:.2f},{y2 - y1:.2f},1,-1,-1,-1")
    out_file.write_text("\n".join(rows) + "\n")


def score(gt: Path, pred: Path):
    out = subprocess.run([SILLAGE, "eval", "mot", "--gt", str(gt), "--pred", str(pred), "--json"],
                         check=True, capture_output=True, text=True).stdout
    combined = json.loads(out)["combined"]["metrics"]
    return combined["clear"]["mota"], combined["identity"]["idf1"]


def main():
    print(f"{'sequence':<16} {'tracker':<10} {'MOTA ref':>9} {'MOTA ours':>10} {'IDF1 ref':>9} {'IDF1 ours':>10}")
    with tempfile.TemporaryDirectory() as tmp:
        for seq in sequences():
            det, gt = seq / "det" / "det.txt", seq / "gt" / "gt.txt"
            for name, reference in [("sort", reference_sort), ("bytetrack", reference_bytetrack)]:
                ref, ours = Path(tmp) / f"{seq.name}_{name}_ref.txt", Path(tmp) / f"{seq.name}_{name}.txt"
                reference(det, ref)
                subprocess.run([SILLAGE, "track", "boxes", "--tracker", name, "--detections",
                                str(det), "--out", str(ours)], check=True, capture_output=True)
                (ma, ia), (mb, ib) = score(gt, ref), score(gt, ours)
                print(f"{seq.name:<16} {name:<10} {ma:>9.4f} {mb:>10.4f} {ia:>9.4f} {ib:>10.4f}")


if __name__ == "__main__":
    main()
