#!/usr/bin/env python3
"""Plot demod-compare results: mean step responses before (dashed) and after (solid) the
common output filter, mean AM responses after it (from the CSV), and MSE / bandwidth per
demodulator (from the JSON).

usage: plot.py RESULTS.json RESPONSES.csv OUT.png
"""
import csv
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

DEMODS = ["lmsd", "rlsd", "kfd", "mult"]
SETS = ["thesis", "equal_bandwidth"]
COLOURS = {"lmsd": "C0", "rlsd": "C1", "kfd": "C2", "mult": "C3"}


def load_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    head, body = rows[0], rows[1:]
    cols = {name: [float(r[i]) for r in body] for i, name in enumerate(head)}
    return cols


def main(argv):
    if len(argv) != 4:
        print(__doc__, file=sys.stderr)
        return 2
    with open(argv[1]) as f:
        res = json.load(f)
    cols = load_csv(argv[2])
    proto = res["protocol"]
    t_ms = [1e3 * t for t in cols["t_s"]]
    amp = proto["amplitude"]

    fig, ax = plt.subplots(3, 2, figsize=(12, 11))
    for j, s in enumerate(SETS):
        for d in DEMODS:
            r = next(x for x in res["results"] if x["demodulator"] == d and x["set"] == s)
            bw = "none" if r["bw_3db_hz"] is None else "%.0f Hz" % r["bw_3db_hz"]
            label = "%s (param %.4g, bw %s)" % (d, r["param"], bw)
            ax[0][j].plot(t_ms, [y / amp for y in cols["step_%s_%s" % (s, d)]],
                          color=COLOURS[d], label=label)
            ax[0][j].plot(t_ms, [y / amp for y in cols["raw_%s_%s" % (s, d)]],
                          color=COLOURS[d], linestyle="--", linewidth=0.6, alpha=0.6)
            ax[1][j].plot(t_ms, [y / amp for y in cols["am_%s_%s" % (s, d)]],
                          color=COLOURS[d], label=d)
        ax[0][j].axhspan(1 - proto["settle_band"], 1 + proto["settle_band"], color="0.9",
                         label="settling band +-%.0f %%" % (100 * proto["settle_band"]))
        # One legend entry for every dashed trace (each demodulator's own colour).
        ax[0][j].plot([], [], color="0.4", linestyle="--", linewidth=0.6,
                      label="dashed: before the output filter")
        ax[0][j].set_title("%s: mean step / A (dashed: before output filter)" % s, fontsize=10)
        ax[0][j].set_xlabel("t [ms]")
        ax[0][j].set_ylabel("output / step amplitude A [1]")
        ax[0][j].set_xlim(0, 0.5e3 * proto["mse_window_start_s"])
        ax[0][j].set_ylim(-0.1, 1.4)
        ax[0][j].legend(fontsize=7)
        ax[1][j].set_title("%s: mean AM (%.0f Hz) response / A" % (s, proto["am_hz"]))
        ax[1][j].set_xlabel("t [ms]")
        ax[1][j].set_ylabel("output / A [1]")
        ax[1][j].legend(fontsize=7)
        ax[0][j].grid(True)
        ax[1][j].grid(True)

    x = range(len(DEMODS))
    base = {"mse_db": min(r["mse_db"] for r in res["results"]) - 1.0, "bw_3db_hz": 0.0}
    for j, (key, title) in enumerate([("mse_db", "steady-state MSE after the output filter [dB]"),
                                      ("bw_3db_hz", "measured -3 dB bandwidth [Hz] (mult "
                                       "thesis: none)")]):
        for k, s in enumerate(SETS):
            vals = []
            for d in DEMODS:
                r = next(v for v in res["results"] if v["demodulator"] == d and v["set"] == s)
                vals.append(float("nan") if r[key] is None else r[key] - base[key])
            bars = ax[2][j].bar([i + 0.4 * k for i in x], vals, width=0.4, bottom=base[key],
                                label=s)
            ax[2][j].bar_label(bars, fmt="%.2f" if key == "mse_db" else "%.0f", fontsize=7,
                               labels=["" if v != v else
                                       ("%.2f" if key == "mse_db" else "%.0f") % (v + base[key])
                                       for v in vals])
        ax[2][j].set_xticks([i + 0.2 for i in x])
        ax[2][j].set_xticklabels(DEMODS)
        ax[2][j].set_title(title)
        ax[2][j].set_ylabel("MSE [dB]" if key == "mse_db" else "-3 dB bandwidth [Hz]")
        ax[2][j].legend(fontsize=7, loc="lower right")
        ax[2][j].grid(True, axis="y")

    fig.suptitle("Demodulator comparison (thesis 5.4.3), %d runs, sigma %.3g, output filter "
                 "Butterworth %d / %.0f Hz" % (proto["runs"], proto["noise_sigma"],
                                               proto["output_filter_order"],
                                               proto["output_filter_cutoff_hz"]))
    fig.tight_layout()
    fig.savefig(argv[3], dpi=90)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
