#!/usr/bin/env python3
"""The timeline page of `flatmarch history report`: the charts (matplotlib) of the series in
TIMELINE.json, in the template timeline.html.j2 beside this script (Jinja).

    make_timeline.py -o OUT TIMELINE.json        OUT/index.html, self-contained

TIMELINE.json is what `flatmarch history report` worked out from the database (every series, its
change points, the findings, open regressions first): this script draws it and computes no
change point. Runs on Debian's python3 with python3-matplotlib and python3-jinja2.
"""
import argparse
import base64
import io
import json
import math
import os
import sys

import jinja2
import markupsafe
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

PALETTE = ["#1f77b4", "#2ca02c", "#d62728", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf"]
# The figures of a report's case drawn per backend and scene: a timing, the cost every backend of
# a method shares, and the CPU's count of the work where the machine counts it.
CHARTED = [("rays_per_s", "Mrays/s", 1e-6), ("steps_mean", "mean steps per ray", 1.0),
           ("instructions_per_ray", "instructions a ray (CPU's count)", 1.0)]


def figure_html(fig, alt):
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=80, bbox_inches="tight")
    plt.close(fig)
    data = base64.b64encode(buf.getvalue()).decode("ascii")
    return markupsafe.Markup('<img class="chart" alt="{}" src="data:image/png;base64,{}">').format(alt, data)


def report_case(name):
    """(backend, method, scene) of a report's case "report/BACKEND/METHOD/SCENE/WxH", or None."""
    parts = name.split("/")
    return tuple(parts[1:4]) if len(parts) == 5 and parts[0] == "report" else None


def backend_charts(timeline):
    """Per machine and backend of the reports' cases, one chart a figure: a panel per scene, a
    line per method over the runs, each change point a vertical line (red where worse)."""
    runs = {r["id"]: k for k, r in enumerate(timeline["runs"])}
    commits = [r["commit"][:7] for r in timeline["runs"]]
    groups = {}  # (machine, backend) -> {figure: {scene: [series]}}
    for s in timeline["series"]:
        case = report_case(s["case"])
        if case and s["figure"] in dict((f, u) for f, u, _ in CHARTED):
            backend, method, scene = case
            groups.setdefault((s["machine"], backend), {}).setdefault(s["figure"], {}).setdefault(
                scene, []).append((method, s))
    charts = []
    for (machine, backend), figures in sorted(groups.items()):
        drawn = []
        for figure, unit, scale in CHARTED:
            scenes = figures.get(figure)
            if not scenes:
                continue
            cols = min(4, len(scenes))
            rows = math.ceil(len(scenes) / cols)
            fig, axes = plt.subplots(rows, cols, figsize=(3.6 * cols, 2.4 * rows), squeeze=False)
            for ax in axes.flat[len(scenes):]:
                ax.axis("off")
            methods = sorted({m for lines in scenes.values() for m, _ in lines})
            for ax, (scene, lines) in zip(axes.flat, sorted(scenes.items())):
                for method, s in lines:
                    xs = [runs[p["run"]] for p in s["points"]]
                    ax.plot(xs, [p["value"] * scale for p in s["points"]], "-o", ms=3,
                            color=PALETTE[methods.index(method) % len(PALETTE)], label=method)
                    for c in s["changes"]:
                        # The line between the runs either side; the first run after it ringed.
                        colour = "#d62728" if c["worse"] else "#2ca02c"
                        ax.axvline(runs[c["run"]] - 0.5, color=colour, ls="--", lw=1.2)
                        ax.plot(runs[c["run"]], s["points"][c["at"]]["value"] * scale, "o", ms=9, mfc="none",
                                mec=colour, mew=1.5)
                if figure == "rays_per_s":  # methods apart by orders: a step of each shows alike
                    ax.set_yscale("log")
                ax.set_title(scene, fontsize=8)
                ax.tick_params(labelsize=6)
                ax.grid(True, alpha=0.3)
            axes.flat[0].legend(fontsize=6)
            axes.flat[0].set_ylabel(unit, fontsize=7)
            ticks = sorted({runs[p["run"]] for lines in scenes.values() for _, s in lines for p in s["points"]})
            for ax in axes.flat[:len(scenes)]:
                ax.set_xticks(ticks, [commits[t] for t in ticks], rotation=90, fontsize=5)
            fig.tight_layout()
            drawn.append(figure_html(fig, f"{backend}, {figure}"))
        charts.append({"machine": machine, "backend": backend, "charts": drawn})
    return charts


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("timeline", help="timeline.json of flatmarch history report")
    parser.add_argument("-o", "--out", required=True, help="output folder")
    args = parser.parse_args()
    try:
        with open(args.timeline) as f:
            timeline = json.load(f)
    except (OSError, ValueError) as e:
        sys.exit(f"error: {args.timeline}: {e}")
    if not isinstance(timeline, dict) or "series" not in timeline:
        sys.exit(f"error: {args.timeline}: not the data of `flatmarch history report`")
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(os.path.dirname(os.path.abspath(__file__))),
                             autoescape=True, undefined=jinja2.StrictUndefined, trim_blocks=True,
                             lstrip_blocks=True)
    page = env.get_template("timeline.html.j2").render(t=timeline, backends=backend_charts(timeline))
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "index.html"), "w") as f:
        f.write(page)
    return 0


if __name__ == "__main__":
    sys.exit(main())
