#!/usr/bin/env python3
"""Draw a ghostfx study's error-versus-cost plot with matplotlib.

`ghostfx study` writes the points it plots to `plot.csv` beside its table and runs this script on
it; edit the script (colours, axes, annotations) and run it again on the same file:

    python3 scripts/plot_study.py out/study_dam_break/plot.csv -o study.png --title "dam break"

plot.csv has one row per plotted run: `series,label,<cost>,<error>,pareto`. The third and fourth
column names are the axis labels; `pareto` is 1 for the runs no other run beats in both cost and
error (computed by ghostfx, cmd/StudyPlot.cc), which are joined by a line in order of cost and
labelled.
"""

import argparse
import csv
import os
import sys


def read_points(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows or len(rows[0]) != 5 or rows[0][0] != "series" or rows[0][4] != "pareto":
        raise ValueError(f"{path}: expected the header series,label,<cost>,<error>,pareto")
    header, points = rows[0], []
    for n, row in enumerate(rows[1:], start=2):
        if len(row) != 5:
            raise ValueError(f"{path}:{n}: expected 5 fields, found {len(row)}")
        try:
            points.append((row[0], row[1], float(row[2]), float(row[3]), row[4] == "1"))
        except ValueError:
            raise ValueError(f"{path}:{n}: '{row[2]}', '{row[3]}' are not numbers") from None
    if not points:
        raise ValueError(f"{path}: no points to plot")
    return header[2], header[3], points


def draw(cost_name, error_name, points, title, out, linear):
    import matplotlib

    matplotlib.use("Agg")  # no display on a render farm
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 5.6), dpi=100, layout="constrained")
    series = list(dict.fromkeys(p[0] for p in points))
    for name in series:
        xs = [p[2] for p in points if p[0] == name]
        ys = [p[3] for p in points if p[0] == name]
        ax.scatter(xs, ys, s=36, label=name or "runs", zorder=3)
    front = sorted((p for p in points if p[4]), key=lambda p: (p[2], p[3]))
    if front:
        ax.plot([p[2] for p in front], [p[3] for p in front], color="0.2", lw=1.2,
                zorder=2, label="Pareto front")
        ax.scatter([p[2] for p in front], [p[3] for p in front], s=110, facecolors="none",
                   edgecolors="0.2", linewidths=1.2, zorder=4)
        for p in front:
            if p[1]:
                ax.annotate(p[1], (p[2], p[3]), xytext=(6, 5), textcoords="offset points",
                            fontsize=8)
    if not linear:
        ax.set_xscale("log")
        ax.set_yscale("log")
    ax.set_xlabel(cost_name)
    ax.set_ylabel(error_name)
    if title:
        ax.set_title(title)
    ax.grid(True, which="major", alpha=0.35)
    ax.legend(loc="center left", bbox_to_anchor=(1.01, 0.5), fontsize=9, frameon=False)
    # Written beside the target and renamed, so an interrupted plot leaves no half a file.
    tmp = out + ".tmp.png"
    fig.savefig(tmp)
    plt.close(fig)
    os.replace(tmp, out)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("points", help="plot.csv written by ghostfx study")
    parser.add_argument("-o", "--output", help="the image (.png, .pdf or .svg); "
                        "default: study.png beside the points")
    parser.add_argument("--title", default="", help="title above the plot")
    parser.add_argument("--linear", action="store_true", help="linear axes instead of log")
    args = parser.parse_args()
    out = args.output or os.path.join(os.path.dirname(args.points) or ".", "study.png")
    try:
        cost, error, points = read_points(args.points)
        if not args.linear:
            bad = [p for p in points if not (p[2] > 0 and p[3] > 0)]
            if bad:
                raise ValueError(f"{args.points}: run '{bad[0][1]}' has {cost} = {bad[0][2]}, "
                                 f"{error} = {bad[0][3]}: a log axis needs values > 0 "
                                 "(--linear draws it)")
        draw(cost, error, points, args.title, out, args.linear)
    except ImportError as e:
        print(f"plot_study.py: error: {e} (Debian: apt-get install python3-matplotlib)",
              file=sys.stderr)
        return 1
    except (OSError, ValueError) as e:
        print(f"plot_study.py: error: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
