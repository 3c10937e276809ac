"""Bar chart of `sillage bench ptv-accuracy --json`: true and false recoveries per case for the
defaults, the old defaults and the per-case tuned setting (docs/img/ptv_family.png).

    sillage bench ptv-accuracy --json > report.json
    python tools/plot_ptv_family.py report.json docs/img/ptv_family.png
"""

import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main(table, out):
    rows = json.load(open(table))
    names = [r["case"]["name"] for r in rows]
    runs = [("defaults", lambda r: r["defaults"]), ("old defaults", lambda r: r["old_defaults"]),
            ("tuned (best of 72)", lambda r: r["tuned"][1] if r["tuned"] else None)]
    x = np.arange(len(rows))
    fig, axes = plt.subplots(2, 1, figsize=(11, 6.5), sharex=True)
    for k, (label, get) in enumerate(runs):
        for ax, key in zip(axes, ["true_pct", "false_pct"]):
            values = [get(r)[key] if get(r) else np.nan for r in rows]
            ax.bar(x + (k - 1) * 0.27, values, 0.27, label=label)
    axes[0].set_ylabel("true recoveries, %")
    axes[1].set_ylabel("false recoveries, %")
    axes[0].legend(loc="upper right", fontsize=8)
    axes[1].set_xticks(x, names, rotation=35, ha="right", fontsize=8)
    half = rows[0]["case"]["half"]
    fig.suptitle(f"sillage bench ptv-accuracy, {half} half ({len(rows)} cases, 512², 10 frames)")
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
