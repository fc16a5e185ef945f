#!/usr/bin/env python3
"""The report's page: the charts (matplotlib) of the results files of `flatmarch report`, in the
template page.html.j2 beside this script (Jinja) with the tables flatmarch worked out from them.

    make_report.py -o OUT --tables PAGE.json RESULTS.json        one machine: OUT/index.html
    make_report.py -o OUT --tables PAGE.json --previous OLD.json RESULTS.json
                                                  the same, with the change per case since OLD
    make_report.py -o OUT --tables PAGE.json A.json B.json ...    machines compared

PAGE.json holds every count, group and change the page's tables show (reports/page.hpp): this
script computes none of them, it draws. `flatmarch report` writes PAGE.json (OUT/page.json) and
calls this script; run `flatmarch report RESULTS.json -o OUT` to make a page again. The page is
self-contained: charts and gallery images are embedded (PNG, base64). Runs on Debian's python3
with python3-matplotlib and python3-jinja2.
"""
import argparse
import base64
import io
import json
import math
import multiprocessing
import os
import sys

import jinja2
import markupsafe
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import LogNorm  # noqa: E402
from matplotlib.patheffects import withStroke  # noqa: E402
from matplotlib.ticker import LogLocator  # noqa: E402

# Each backend a colour and each method a marker, by its place in the tables' lists (the
# registry's), so that every chart of a page draws them alike.
PALETTE = ["#1f77b4", "#2ca02c", "#d62728", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf"]
MARKERS = ["o", "s", "^", "D", "v", "P"]
BACKEND_COLOURS = {}
METHOD_MARKERS = {}


def use_lists(tables):
    BACKEND_COLOURS.clear()
    BACKEND_COLOURS.update({b: PALETTE[k % len(PALETTE)] for k, b in enumerate(tables.get("backends", []))})
    METHOD_MARKERS.clear()
    METHOD_MARKERS.update({m: MARKERS[k % len(MARKERS)] for k, m in enumerate(tables.get("methods", []))})


def log_axes(ax):
    """Both axes logarithmic, a grid line at each power of ten and at its 2x and 5x: matplotlib's
    own minor ticks (all of 2x-9x) made each chart's layout a few times slower."""
    for axis, scale in ((ax.xaxis, ax.set_xscale), (ax.yaxis, ax.set_yscale)):
        scale("log")
        axis.set_minor_locator(LogLocator(base=10, subs=(2.0, 5.0)))


def figure_html(fig, alt):
    """The figure as an embedded PNG."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90, bbox_inches="tight")
    plt.close(fig)
    data = base64.b64encode(buf.getvalue()).decode("ascii")
    return markupsafe.Markup('<img class="chart" alt="{}" src="data:image/png;base64,{}">').format(alt, data)


def image_html(path, alt):
    """An image of the run's images folder, embedded."""
    if not os.path.exists(path):
        return markupsafe.Markup('<span class="missing">no image</span>')
    with open(path, "rb") as f:
        data = base64.b64encode(f.read()).decode("ascii")
    return markupsafe.Markup('<img class="frame" alt="{0}" title="{0}" src="data:image/png;base64,{1}">').format(
        alt, data)


def pct(share):
    return f"{100 * share:.3g}%"


def mrays(rays):
    return f"{rays / 1e6:.3g}" if rays else "-"


# --- Charts of one machine.


def device_time_chart(results):
    """Each GPU backend's frames split by the device's own clock: the march, the read-back, the rest."""
    ranked = [b for b in results.get("ranking", []) if b.get("device_time")]
    if not ranked:
        return ""
    fig, ax = plt.subplots(figsize=(7.0, 0.6 + 0.45 * len(ranked)))
    names = [b["backend"] for b in ranked]
    left = [0.0] * len(ranked)
    for key, label, colour in (("march_share", "march", "#1f77b4"), ("readback_share", "read-back", "#ff7f0e"),
                               ("rest_share", "rest", "#bbbbbb")):
        widths = [100 * b["device_time"][key] for b in ranked]
        ax.barh(names, widths, left=left, color=colour, label=label)
        left = [a + w for a, w in zip(left, widths)]
    ax.set_xlabel("% of a frame's wall time")
    ax.set_xlim(0, 100)
    ax.invert_yaxis()
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    return figure_html(fig, "each GPU backend's frame split by the device's clock")


def speed_accuracy_chart(results, tables):
    cases = results.get("matrix", {}).get("cases", [])
    verdicts = tables["verdicts"]
    types = [t for t in tables["surface_types"] if any(c["surface_type"] == t for c in cases)]
    if not types:
        return ""
    cols = min(3, len(types))
    rows = math.ceil(len(types) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(5.2 * cols, 4.0 * rows), squeeze=False)
    for ax in axes.flat[len(types):]:
        ax.axis("off")
    for ax, t in zip(axes.flat, types):
        for c, v in zip(cases, verdicts):
            if c["surface_type"] != t or "counters" not in c or "accuracy" not in c:
                continue
            a = c["accuracy"]
            y = max(100 * (a["hit_mismatch"] + a["crossings_mismatch"]) / 2, 1e-3)
            x = c["counters"]["rays_per_s"] / 1e6
            colour = BACKEND_COLOURS.get(c["backend"], "k")
            ax.scatter(x, y, s=36, marker=METHOD_MARKERS.get(c["method"], "o"),
                       facecolors=colour if v == "pass" else "none", edgecolors=colour, linewidths=1.3,
                       linestyle="-" if v != "limit" else (0, (1.5, 1)))
            if v == "fail":
                ax.scatter(x, y, s=36, marker="x", color=colour, linewidths=1.0)
        log_axes(ax)
        ax.set_ylim(5e-4, 100)
        ax.set_title(f"{t} surfaces")
        ax.set_xlabel("speed: Mrays/s (log)")
        ax.set_ylabel("decided pixels wrong: hit, crossings (%)")
        ax.grid(True, which="both", alpha=0.3)
        ax.axhline(1e-3, color="grey", lw=0.5)
    handles = [plt.Line2D([], [], color=col, marker="o", ls="", label=b) for b, col in BACKEND_COLOURS.items()]
    handles += [plt.Line2D([], [], color="k", marker=mk, ls="", label=m) for m, mk in METHOD_MARKERS.items()]
    handles += [plt.Line2D([], [], color="k", marker="o", mfc="none", ls="", label="limit (hollow)"),
                plt.Line2D([], [], color="k", marker="x", ls="", label="fail (crossed)")]
    fig.legend(handles=handles, loc="upper center", ncol=8, bbox_to_anchor=(0.5, 0.0))
    fig.tight_layout()
    return figure_html(fig, "speed against accuracy")


def steps_chart(results):
    cases = results.get("matrix", {}).get("cases", [])
    scenes = sorted({c["scene"] for c in cases})
    columns = sorted({(c["backend"], c["method"]) for c in cases})
    grid = [[math.nan] * len(columns) for _ in scenes]
    for c in cases:
        if "counters" in c:
            grid[scenes.index(c["scene"])][columns.index((c["backend"], c["method"]))] = c["counters"]["steps_mean"]
    finite = [v for row in grid for v in row if not math.isnan(v) and v > 0]
    if not finite:
        return ""
    fig, ax = plt.subplots(figsize=(1.0 + 0.55 * len(columns), 1.2 + 0.32 * len(scenes)))
    im = ax.imshow(grid, aspect="auto", cmap="viridis", norm=LogNorm(vmin=min(finite), vmax=max(max(finite), 2)))
    for i in range(len(scenes)):
        for j in range(len(columns)):
            if not math.isnan(grid[i][j]):
                ax.text(j, i, f"{grid[i][j]:.0f}", ha="center", va="center", fontsize=7,
                        color="white" if grid[i][j] < 30 else "black")
    ax.set_yticks(range(len(scenes)), scenes, fontsize=8)
    ax.set_xticks(range(len(columns)), [f"{b}\n{m}" for b, m in columns], fontsize=7, rotation=90)
    fig.colorbar(im, ax=ax, label="mean steps per ray (log)")
    ax.set_title("Kernel steps per ray")
    return figure_html(fig, "steps heatmap")


def sweep_heatmaps(groups, what, methods, precisions, labels, eps_values, codes, steps_norm, t):
    """One surface type's stability or steps heatmaps: a panel per method and precision."""
    fig, axes = plt.subplots(len(precisions), len(methods), squeeze=False, layout="constrained",
                             figsize=(3.6 * len(methods) + 1.2, 3.3 * len(precisions)))
    stability = what == "stability"
    for i, prec in enumerate(precisions):
        for j, m in enumerate(methods):
            ax = axes[i][j]
            g = next((g for g in groups if g["method"] == m and g["precision"] == prec), None)
            if g is None:
                ax.axis("off")
                continue
            cells = {(c["eps"], c["offset_label"]): c for c in g["grid"]}
            grid = [[math.nan] * len(labels) for _ in eps_values]
            for r, e in enumerate(eps_values):
                for k, lab in enumerate(labels):
                    c = cells.get((e, lab))
                    if c is not None and not c["errors"]:
                        grid[r][k] = max(100 * c["hit_mismatch"], 1e-3) if stability else max(c["steps_mean"], 1)
            im = ax.imshow(grid, aspect="auto", cmap="magma_r" if stability else "viridis",
                           norm=LogNorm(vmin=1e-3, vmax=100) if stability else steps_norm)
            for r, e in enumerate(eps_values):
                for k, lab in enumerate(labels):
                    c = cells.get((e, lab))
                    if c and stability and c["stable"]:
                        ax.text(k, r, "\u2713", ha="center", va="center", color="#33ff77", fontsize=11,
                                fontweight="bold", path_effects=[withStroke(linewidth=2, foreground="black")])
                    elif c and stability:
                        # Yellow where every scene that does not pass is at its method's limit.
                        at_limit = 0 < c.get("limits", 0) == c["scenes"] - c["passed"] - c["errors"]
                        ax.text(k, r, codes.get(c.get("cause", ""), ""), ha="center", va="center", fontsize=7.5,
                                color="#ffd700" if at_limit else "white",
                                path_effects=[withStroke(linewidth=1.6, foreground="black")])
                    if c and not stability and not math.isnan(grid[r][k]):
                        ax.text(k, r, f"{grid[r][k]:.0f}", ha="center", va="center", fontsize=6,
                                color="white" if grid[r][k] < 40 else "black")
            rec = g.get("recommended")
            if rec:
                ax.plot(labels.index(rec["offset_label"]), eps_values.index(rec["eps"]), marker="*", ms=16,
                        mfc="none", mec="#ff8c00" if rec.get("fallback") else "#00bfff", mew=2)
            ax.set_xticks(range(len(labels)), labels, rotation=60, fontsize=7)
            ax.set_yticks(range(len(eps_values)), [f"{e:g}" for e in eps_values], fontsize=7)
            ax.set_title(f"{m}, {prec}", fontsize=9)
            if j == 0:
                ax.set_ylabel("eps")
            if i == len(precisions) - 1:
                ax.set_xlabel("offset")
    fig.colorbar(im, ax=axes, shrink=0.8,
                 label="hit wrong, % of decided pixels" if stability else "mean steps per ray")
    return figure_html(fig, f"{what} heatmap, {t}")


def sweep_types(tables):
    """The surface types of the tables' sweep, in its order."""
    return [entry["type"] for entry in (tables.get("sweep") or {}).get("types", [])]


def sweep_charts(results, tables, t):
    """Surface type t's charts of the sweep: the stability and steps heatmaps and the Pareto chart
    of each grid point's time against its error."""
    sweep = results.get("sweep", {})
    labels = sweep["options"]["offset_labels"]
    eps_values = sorted(sweep["options"]["eps"], reverse=True)
    codes = tables["sweep"]["codes"]
    groups = [g for g in sweep["analysis"] if g["surface_type"] == t]
    methods = [m for m in tables["methods"] if any(g["method"] == m for g in groups)]
    precisions = [p for p in ["f32", "f64"] if any(g["precision"] == p for g in groups)]
    steps = [c["steps_mean"] for g in groups for c in g["grid"] if not c["errors"] and c["steps_mean"] > 0]
    steps_norm = LogNorm(vmin=max(1, min(steps)), vmax=max(2, max(steps))) if steps else LogNorm(1, 2)
    drawn = [sweep_heatmaps(groups, what, methods, precisions, labels, eps_values, codes, steps_norm, t)
             for what in ("stability", "steps")]
    fig, axes = plt.subplots(1, len(precisions), squeeze=False, figsize=(5.0 * len(precisions), 3.6))
    for ax, prec in zip(axes[0], precisions):
        for g in groups:
            if g["precision"] != prec:
                continue
            col = PALETTE[tables["methods"].index(g["method"]) % len(PALETTE)]
            pts = [c for c in g["grid"] if not c["errors"]]
            ax.scatter([c["time_ms"] for c in pts], [max(100 * c["hit_mismatch"], 1e-3) for c in pts], s=12,
                       color=col, alpha=0.35)
            front = g["pareto"]
            ax.plot([p["time_ms"] for p in front], [max(100 * p["hit_mismatch"], 1e-3) for p in front],
                    "-o", color=col, ms=4, label=f'{g["method"]} front')
        log_axes(ax)
        ax.set_xlabel("time per frame, ms (log)")
        ax.set_ylabel("hit wrong, % of decided pixels")
        ax.set_title(f"{t}, {prec}: speed against accuracy")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    return drawn + [figure_html(fig, f"pareto, {t}")]


def scaling_chart(results):
    series = results.get("scaling", {}).get("series", [])
    if not series:
        return ""
    axes_names = [("pixels", "pixels per frame"), ("edges", "edges of the surface"),
                  ("max_distance", "path length (max_distance)")]
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.6))
    for ax, (axis, label) in zip(axes, axes_names):
        for s in series:
            if s["axis"] != axis or not s["x"]:
                continue
            staircase = "staircase" in s["family"]
            ax.plot(s["x"], s["time_ms"], "--" if staircase else "-", marker=METHOD_MARKERS.get(s["method"], "o"),
                    ms=4, color=BACKEND_COLOURS.get(s["backend"], "k"),
                    label=f'{s["backend"]} {s["method"]}{" staircase" if staircase else ""}: slope {s["slope"]:.2f}')
        log_axes(ax)
        ax.set_xlabel(label + " (log)")
        ax.set_ylabel("ms per frame (log)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2)
    fig.tight_layout()
    return figure_html(fig, "scaling")


# --- Machines compared.


def machines_chart(all_results, names):
    """Each backend's speed on each machine, its device named on its bar."""
    backends = sorted({b["backend"] for r in all_results for b in r.get("ranking", [])})
    fig, ax = plt.subplots(figsize=(2 + 1.6 * len(backends), 4.5))
    width = 0.8 / len(all_results)
    for i, (r, name) in enumerate(zip(all_results, names)):
        ranked = {b["backend"]: b for b in r.get("ranking", [])}
        # A backend a machine did not measure gets no bar (not a zero, which a log axis cannot draw).
        measured = [(k, b) for k, b in enumerate(backends) if ranked.get(b, {}).get("rays_per_s")]
        bars = ax.bar([k + i * width for k, _ in measured], [ranked[b]["rays_per_s"] / 1e6 for _, b in measured],
                      width, label=name)
        # The same backend is a GPU on one machine and a software rasteriser on another.
        for bar, (_, b) in zip(bars, measured):
            d = ranked[b].get("device")
            if d:
                ax.annotate(d["name"].split(" (")[0][:24] + (" (sw)" if d.get("software") else ""),
                            (bar.get_x() + bar.get_width() / 2, bar.get_height()), rotation=90, fontsize=6,
                            ha="center", va="bottom", xytext=(0, 2), textcoords="offset points")
    ax.set_xticks([k + 0.4 - width / 2 for k in range(len(backends))], backends)
    ax.set_ylabel("Mrays/s, geometric mean over the gallery")
    ax.set_yscale("log")
    bottom, top = ax.get_ylim()
    ax.set_ylim(bottom, top * 30)  # room for the device names above the bars
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=1)
    ax.grid(True, axis="y", which="both", alpha=0.3)
    return figure_html(fig, "speed per machine")


# --- The page.


def template(images):
    """The page's template, beside this script (a link to it in the build tree, installed beside
    it), with the filters and the image function it draws by; `images`: the run's images folder."""
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(os.path.dirname(os.path.abspath(__file__))),
                             autoescape=True, undefined=jinja2.StrictUndefined, trim_blocks=True,
                             lstrip_blocks=True)
    env.filters["verdict"] = lambda v: markupsafe.Markup('<span class="verdict {0}">{0}</span>').format(v)
    env.filters["mrays"] = mrays
    env.filters["pct"] = pct
    env.globals["image"] = lambda path, alt: image_html(os.path.join(images, path), alt)
    return env.get_template("page.html.j2").module


# The charts a forked worker draws: (function, arguments) by index, set before the pool forks.
_CHART_CALLS = []


def _draw_chart(index):
    function, arguments = _CHART_CALLS[index]
    return function(*arguments)


def draw_charts(calls):
    """Each named (function, arguments) called, on every core at once where there are several (the
    charts are most of the page's time). The calls are given out in their order, one at a time."""
    global _CHART_CALLS
    names = list(calls)
    workers = min(len(calls), len(os.sched_getaffinity(0)))
    if workers < 2 or "fork" not in multiprocessing.get_all_start_methods():
        return {n: calls[n][0](*calls[n][1]) for n in names}
    _CHART_CALLS = [calls[n] for n in names]
    with multiprocessing.get_context("fork").Pool(workers) as pool:
        return dict(zip(names, pool.map(_draw_chart, range(len(names)), chunksize=1)))


def read_json(path, what):
    """A JSON file; exits with a message where it is missing or is not JSON."""
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        sys.exit(f"error: {what} {path}: {e}")


def read_results(path):
    """A results file of `flatmarch report`; exits with a message for anything else."""
    r = read_json(path, "results file")
    missing = [k for k in ("fingerprint", "matrix", "ranking") if not isinstance(r, dict) or k not in r]
    if missing:
        sys.exit(f'error: {path}: no "{missing[0]}": not a results file of `flatmarch report`')
    return r


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("results", nargs="+", help="results.json files of flatmarch report")
    parser.add_argument("-o", "--out", required=True, help="output folder")
    parser.add_argument("--tables", required=True,
                        help="the page's tables, worked out by flatmarch from the same files (OUT/page.json)")
    parser.add_argument("--previous", help="the earlier run's results.json the tables compare with")
    args = parser.parse_args()
    all_results = [read_results(path) for path in args.results]
    tables = read_json(args.tables, "tables")
    if not isinstance(tables, dict) or ("names" in tables) == (len(all_results) == 1):
        sys.exit(f"error: {args.tables}: not the tables of these {len(all_results)} results files: "
                 "make the page with `flatmarch report RESULTS.json... -o OUT`")
    use_lists(tables)
    os.makedirs(args.out, exist_ok=True)
    if len(all_results) == 1:
        results = all_results[0]
        page = template(os.path.join(os.path.dirname(os.path.abspath(args.results[0])), "images"))
        # A chart a task, the dearest first, so that the cores finish together.
        types = sweep_types(tables)
        calls = {"speed": (speed_accuracy_chart, (results, tables))}
        calls.update({"sweep/" + t: (sweep_charts, (results, tables, t)) for t in types})
        calls.update({"scaling": (scaling_chart, (results,)), "steps": (steps_chart, (results,)),
                      "device": (device_time_chart, (results,))})
        charts = draw_charts(calls)
        charts["sweep"] = [charts.pop("sweep/" + t) for t in types]
        previous = read_results(args.previous) if args.previous else None
        html = page.page("flatmarch report", page.report(results, tables, charts, previous, args.previous))
    else:
        page = template("")
        html = page.page("flatmarch: machines compared",
                         page.machines(all_results, tables, machines_chart(all_results, tables["names"])))
    with open(os.path.join(args.out, "index.html"), "w") as f:
        f.write(str(html))
    return 0


if __name__ == "__main__":
    sys.exit(main())
