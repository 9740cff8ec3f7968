#!/usr/bin/env python3
"""Cradle's research figures: draws the PNGs a run's figure spec (JSON, written by the CLI next
to them) describes, with matplotlib.

    python3 python/cradle_figures.py results/self_touch/plots/figures.json

Each figure is {"file", "kind": "line" | "bar", "title", "width", "height", ...}: line plots
have "x_label", "y_label", "series" [{"label", "x", "y", "points"}], "h_lines" [[y, label]] and
an optional "y_range"; bar charts "y_label", "categories", "groups", "values" [group][category]
and an optional "y_range". Missing values (null) are gaps. Exit status 3 without matplotlib.
"""
import json
import math
import sys

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("cradle_figures: matplotlib is not installed", file=sys.stderr)
    sys.exit(3)


def values(v):
    return [math.nan if x is None else x for x in v]


def line_plot(ax, figure):
    for s in figure["series"]:
        y = values(s["y"])
        x = values(s["x"]) if s.get("x") else list(range(len(y)))
        if s.get("points"):
            ax.scatter(x, y, s=12, label=s.get("label") or None)
        else:
            # A line through fewer than two points draws nothing: mark the point instead.
            lone = sum(1 for v in y if not math.isnan(v)) < 2
            ax.plot(x, y, linewidth=1.5, marker="o" if lone else None,
                    label=s.get("label") or None)
    for y, label in figure.get("h_lines", []):
        ax.axhline(y, linestyle="--", color="0.4", linewidth=1)
        ax.annotate(label, (0, y), xycoords=("axes fraction", "data"), xytext=(4, 3),
                    textcoords="offset points", fontsize=8, color="0.3")
    ax.set_xlabel(figure.get("x_label", ""))


def bar_chart(ax, figure):
    groups = figure["values"]
    categories = figure["categories"]
    width = 0.8 / max(1, len(groups))
    for g, row in enumerate(groups):
        xs = [c + (g - (len(groups) - 1) / 2) * width for c in range(len(row))]
        label = figure["groups"][g] if g < len(figure.get("groups", [])) else None
        ax.bar(xs, values(row), width=width, label=label)
    ax.set_xticks(range(len(categories)))
    slant = len(categories) > 8
    ax.set_xticklabels(categories, rotation=45 if slant else 0, ha="right" if slant else "center",
                       fontsize=8)


def draw(figure):
    fig, ax = plt.subplots(figsize=(figure["width"] / 100, figure["height"] / 100), dpi=100)
    (line_plot if figure["kind"] == "line" else bar_chart)(ax, figure)
    ax.set_title(figure.get("title", ""))
    ax.set_ylabel(figure.get("y_label", ""))
    if figure.get("y_range"):
        ax.set_ylim(*figure["y_range"])
    ax.grid(alpha=0.3)
    if any(h.get_label() and not h.get_label().startswith("_")
           for h in ax.get_legend_handles_labels()[0]):
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(figure["file"])
    plt.close(fig)


def main():
    if len(sys.argv) != 2:
        print("usage: cradle_figures.py SPEC.json", file=sys.stderr)
        return 2
    with open(sys.argv[1]) as f:
        spec = json.load(f)
    for figure in spec["figures"]:
        draw(figure)
    return 0


if __name__ == "__main__":
    sys.exit(main())
