#!/usr/bin/env python3
"""The report's page: charts (matplotlib) and tables from the results files of `flatmarch report`.

    make_report.py -o OUT RESULTS.json            one machine: OUT/index.html
    make_report.py -o OUT A.json B.json ...       machines compared: OUT/index.html

The page is self-contained: charts and gallery images are embedded (PNG, base64). Called by
`flatmarch report`; runs on Debian's python3 with python3-matplotlib.
"""
import argparse
import base64
import html
import io
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import LogNorm  # noqa: E402
from matplotlib.patheffects import withStroke  # noqa: E402

# The kernel's backends and methods, in the order flatmarch lists them: read from the results'
# "registry" (use_registry), never restated here. Each gets a colour or marker by its place.
METHODS = []
BACKEND_COLOURS = {}
METHOD_MARKERS = {}
PALETTE = ["#1f77b4", "#2ca02c", "#d62728", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf"]
MARKERS = ["o", "s", "^", "D", "v", "P"]
SURFACE_TYPES = ["prism", "mirror", "dilation", "reflection", "rotation", "translation"]
FAILURES = ["stuck", "wrong_edge", "missed_object", "phantom_hit", "early_escape", "late_escape", "leak"]


def use_registry(all_results):
    """Takes the backend and method lists from the results (the first that carries them; results
    written before they did: the backends and methods their cases name, in order of appearance)."""
    backends, methods = [], []
    for r in all_results:
        if "registry" in r:
            backends, methods = r["registry"]["backends"], r["registry"]["methods"]
            break
    if not backends:
        for r in all_results:
            for c in r.get("matrix", {}).get("cases", []):
                if c["backend"] not in backends:
                    backends.append(c["backend"])
                if c["method"] not in methods:
                    methods.append(c["method"])
    METHODS[:] = methods
    BACKEND_COLOURS.clear()
    BACKEND_COLOURS.update({b: PALETTE[k % len(PALETTE)] for k, b in enumerate(backends)})
    METHOD_MARKERS.clear()
    METHOD_MARKERS.update({m: MARKERS[k % len(MARKERS)] for k, m in enumerate(methods)})


def esc(text):
    return html.escape(str(text))


def figure_html(fig, alt):
    """The figure as an embedded PNG."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90, bbox_inches="tight")
    plt.close(fig)
    data = base64.b64encode(buf.getvalue()).decode("ascii")
    return f'<img class="chart" alt="{esc(alt)}" src="data:image/png;base64,{data}">'


def image_html(path, alt):
    if not os.path.exists(path):
        return '<span class="missing">no image</span>'
    with open(path, "rb") as f:
        data = base64.b64encode(f.read()).decode("ascii")
    return f'<img class="frame" alt="{esc(alt)}" title="{esc(alt)}" src="data:image/png;base64,{data}">'


def table(header, rows, cls=""):
    out = [f'<table class="{cls}"><tr>' + "".join(f"<th>{esc(h)}</th>" for h in header) + "</tr>"]
    for row in rows:
        out.append("<tr>" + "".join(c if str(c).startswith("<") else f"<td>{esc(c)}</td>" for c in row) + "</tr>")
    out.append("</table>")
    return "\n".join(out)


def td(text, cls=""):
    return f'<td class="{cls}">{esc(text)}</td>'


def mrays(rays):
    return f"{rays / 1e6:.3g}" if rays else "-"


def pct(share):
    return f"{100 * share:.3g}%"


def device_text(backend):
    """Where a ranked backend ran: its GPU-backend device (marked when software), or the CPU."""
    d = backend.get("device")
    if not d:
        return "CPU"
    return d["name"] + (" (software)" if d.get("software") else "") + (f', {d["driver"]}' if d.get("driver") else "")


def fingerprint_rows(fp):
    cpu = fp.get("cpu", {})
    rows = [
        ("CPU", f'{cpu.get("model", "?")}, {cpu.get("logical_cores", "?")} threads'),
        ("SIMD", f'{cpu.get("isa", "?")} ({cpu.get("simd_lanes", "?")} lanes); compiled in: {", ".join(cpu.get("isas", []))}'),
    ]
    gl = fp.get("opengl", {})
    rows.append(("OpenGL", (f'{gl["renderer"]}' + (f' through {gl["platform"]}' if "platform" in gl else "") +
                            (", software: a rasteriser on the CPU" if gl.get("software") else ""))
                 if "renderer" in gl else "unavailable: " + gl.get("unavailable", "?")))
    vk = fp.get("vulkan", {})
    rows.append(("Vulkan", f'{vk["device"]} ({vk.get("type")}, Vulkan {vk.get("api")}, driver {vk.get("driver")}'
                 + (", software: a rasteriser on the CPU" if vk.get("software") else "") + ")"
                 if "device" in vk else "unavailable: " + vk.get("unavailable", "?")))
    rows.append(("OS", f'{fp.get("os", "?")} on {fp.get("host", "?")}'))
    rows.append(("Libraries", ", ".join(f"{k} {v}" for k, v in fp.get("libraries", {}).items())))
    b = fp.get("build", {})
    rows.append(("Build", f'flatmarch {b.get("flatmarch")}, {b.get("compiler")}, {b.get("type")}'))
    return rows


# --- One machine.


def ranking_section(results):
    rec = results.get("recommendation", {})
    parts = ["<h2 id=ranking>Ranking on this machine and recommended parameters</h2>"]
    if rec.get("backend"):
        parts.append(f'<p class="choice">Use <b>{esc(rec["backend"])}</b> with the <b>{esc(rec["method"])}</b> '
                     f'method: {mrays(rec.get("rays_per_s", 0))} Mrays/s, geometric mean over the gallery. '
                     f'{esc(rec["why"][0].upper() + rec["why"][1:])}. <code>flatmarch select</code> prints this choice.'
                     + (" The analytic method crosses edges exactly and pushes no point: it does not use the offset."
                        if rec["method"] == "analytic" else "") + "</p>")
        rows = []
        for t, p in rec.get("parameters", {}).items():
            src = "the sweep's recommendation" if p["source"] == "sweep" else "defaults: the sweep found no stable point"
            rows.append((t, f'{p["eps"]:g}', f'{p["offset"]:g}', src))
        parts.append(table(["surface type", "eps", "offset", "from"], rows))
    else:
        parts.append(f'<p class="bad">No recommendation: {esc(rec.get("why", ""))}</p>')
    methods = METHODS
    rows = []
    for b in results.get("ranking", []):
        row = [b["rank"], b["backend"], device_text(b), mrays(b["rays_per_s"]),
               f'{b["passed"]}/{b["cases"]}' + (f' ({b["errors"]} errors)' if b["errors"] else "")]
        for m in methods:
            mm = b["methods"].get(m)
            peak = f', {pct(mm["of_peak"])} of peak' if mm and "of_peak" in mm else ""
            row.append(f'{mrays(mm["rays_per_s"])} ({int(mm["passed"])}/{int(mm["cases"])}{peak})' if mm else "-")
        row.append(b["best_method"] or "-")
        rows.append(row)
    parts.append("<p>Backends ranked: those that passed every conformance case first, then by the geometric "
                 "mean of rays per second over every scene and method. Per method: Mrays/s (cases passed; for the "
                 "SIMD backend, the geometric mean of how much of this CPU's peak its frames reach, see Steps). "
                 "A GPU backend names the device it ran on; <i>software</i> marks a rasteriser running on the "
                 "CPU (Mesa's llvmpipe and lavapipe), whose speed says nothing of a GPU's.</p>")
    parts.append(table(["rank", "backend", "device", "Mrays/s", "conform"] + [f"{m} Mrays/s" for m in methods] +
                       ["fastest conforming method"], rows))
    skipped = results.get("matrix", {}).get("skipped", [])
    if skipped:
        parts.append("<p>Skipped: " + "; ".join(f'{esc(s["backend"])} ({esc(s["reason"])})' for s in skipped) + "</p>")
    return "\n".join(parts)


def speed_accuracy_section(cases):
    types = [t for t in SURFACE_TYPES if any(c["surface_type"] == t for c in cases)]
    if not types:
        return ""
    cols = min(3, len(types))
    rows = math.ceil(len(types) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(5.2 * cols, 4.0 * rows), squeeze=False)
    for ax in axes.flat[len(types):]:
        ax.axis("off")
    for ax, t in zip(axes.flat, types):
        for c in cases:
            if c["surface_type"] != t or "counters" not in c or "accuracy" not in c:
                continue
            a = c["accuracy"]
            y = 100 * (a["hit_mismatch"] + a["crossings_mismatch"]) / 2
            ax.scatter(c["counters"]["rays_per_s"] / 1e6, max(y, 1e-3), s=36,
                       marker=METHOD_MARKERS.get(c["method"], "o"),
                       facecolors=BACKEND_COLOURS.get(c["backend"], "k") if a["passed"] else "none",
                       edgecolors=BACKEND_COLOURS.get(c["backend"], "k"), linewidths=1.3)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_ylim(5e-4, 100)
        ax.set_title(f"{t} surfaces")
        ax.set_xlabel("speed: Mrays/s (log)")
        ax.set_ylabel("decided pixels wrong: hit, crossings (%)")
        ax.grid(True, which="both", alpha=0.3)
        ax.axhline(1e-3, color="grey", lw=0.5)
    handles = [plt.Line2D([], [], color=col, marker="o", ls="", label=b) for b, col in BACKEND_COLOURS.items()]
    handles += [plt.Line2D([], [], color="k", marker=mk, ls="", label=m) for m, mk in METHOD_MARKERS.items()]
    handles += [plt.Line2D([], [], color="k", marker="o", mfc="none", ls="", label="failed conformance")]
    fig.legend(handles=handles, loc="lower center", ncol=8, bbox_to_anchor=(0.5, -0.04))
    fig.tight_layout()
    return ("<h2 id=speed>Speed against accuracy, per surface type</h2>"
            "<p>Each point is one backend, method and gallery scene: its speed (timed frames) against the share "
            "of pixels the oracle decides whose hit or crossing count is wrong (mean of the two; zero is drawn "
            "on the bottom line). Hollow: the case failed a conformance threshold. Up and to the left is worse.</p>"
            + figure_html(fig, "speed against accuracy"))


def gallery_section(results, images):
    scenes = results["options"]["scenes"]
    backends = ["oracle"] + [b["backend"] for b in results.get("ranking", [])]
    rows = []
    for s in scenes:
        rows.append([f"<td>{esc(s)}</td>"] + [
            "<td>" + image_html(os.path.join(images, b, s + ".png"), f"{s}, {b}") + "</td>" for b in backends])
    return ("<h2 id=gallery>Gallery, per backend</h2><p>Each scene from its own camera, by the exact oracle "
            f"and by each backend (sphere method, {esc(results['options']['size'])}, the timed frames). In the "
            "translation prisms sphere tracing runs out of steps on many rays (the grey haze), which the "
            "thresholds allow there; the analytic method does not (see the speed chart above).</p>"
            + table(["scene"] + backends, rows, "gallery"))


def steps_heatmap_section(cases):
    scenes = sorted({c["scene"] for c in cases})
    columns = sorted({(c["backend"], c["method"]) for c in cases})
    if not scenes or not columns:
        return ""
    grid = [[math.nan] * len(columns) for _ in scenes]
    for c in cases:
        if "counters" in c:
            grid[scenes.index(c["scene"])][columns.index((c["backend"], c["method"]))] = c["counters"]["steps_mean"]
    fig, ax = plt.subplots(figsize=(1.0 + 0.55 * len(columns), 1.2 + 0.32 * len(scenes)))
    finite = [v for row in grid for v in row if not math.isnan(v) and v > 0]
    if not finite:
        return ""
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
    simd = {(c["scene"], c["method"]): c["counters"] for c in cases
            if "lane_utilisation" in c.get("counters", {})}
    lane_table = ""
    if simd:
        methods = [m for m in METHODS if any(k[1] == m for k in simd)]

        def cell(counters):
            text = pct(counters["lane_utilisation"]) + " lanes"
            if "of_peak" in counters:
                text += f' · {pct(counters["of_peak"])} of peak'
            return text
        lane_table = ("<p>SIMD lane utilisation: the share of packet lanes doing work, over every step of every "
                      "packet (rays of a packet that finish early, or step apart, leave lanes idle); and how close "
                      "to what this CPU can do the frame runs: its kernel steps a second over the peak, the steps a "
                      "second of one room's step on full packets on every core (no lane idle, nothing to shade or "
                      "write, the tables in cache).</p>" +
                      table(["scene"] + methods,
                            [[s] + [cell(simd[(s, m)]) if (s, m) in simd else "-" for m in methods] for s in scenes]))
    return ("<h2 id=steps>Steps per ray</h2><p>The mean number of kernel iterations per ray of the timed frames, per "
            "scene, backend and method: the cost the backends share; backends of one method should agree.</p>"
            + figure_html(fig, "steps heatmap") + lane_table)


def failure_section(cases):
    rows = []
    totals = {}
    for c in cases:
        key = (c["backend"], c["method"])
        t = totals.setdefault(key, {f: 0 for f in FAILURES} | {"cases": 0, "failed": 0, "limits": 0, "errors": 0})
        t["cases"] += 1
        if "error" in c:
            t["errors"] += 1
            continue
        a = c.get("accuracy")
        if not a:
            continue
        verdict = a.get("verdict", "pass" if a["passed"] else "fail")
        t["failed"] += verdict == "fail"
        t["limits"] += verdict == "limit"
        for f in FAILURES:
            t[f] += a["failures"].get(f, 0)
    for (b, m), t in sorted(totals.items()):
        rows.append([b, m, f'{t["cases"] - t["failed"] - t["limits"] - t["errors"]}/{t["cases"]}',
                     td(t["limits"], "bad" if t["limits"] else "")] +
                    [td(t[f], "bad" if t[f] else "") for f in FAILURES])
    out = ["<h2 id=failures>Failures</h2><p>Rays of each failure class over the gallery (decided pixels of the "
           "conformance frames and diverging probe rays), per backend and method, and each case that failed "
           "a threshold, with the checks it failed.</p>",
           table(["backend", "method", "cases passed", "at the method's limit"] + FAILURES, rows)]

    def verdict(c):
        a = c.get("accuracy", {})
        return a.get("verdict", "pass" if a.get("passed", True) else "fail")
    failed = [c for c in cases if "error" in c or verdict(c) == "fail"]
    limits = [c for c in cases if "error" not in c and verdict(c) == "limit"]
    passed = len(cases) - len(failed) - len(limits)
    out.append(f"<p>{passed} cases pass, {len(limits)} are at their method's limit (they fail the "
               "thresholds only through a documented failure mode of the method, such as rays running out "
               f"of max_steps: never counted as a pass), {len(failed)} fail.</p>")
    if failed:
        out.append(table(["case", "failed checks"], [
            [c["name"], c.get("error") or "; ".join(c["accuracy"]["failed_checks"])] for c in failed]))
    if limits:
        out.append(table(["case at its method's limit", "why", "checks beyond the thresholds"], [
            [c["name"], c["accuracy"]["limit"], "; ".join(c["accuracy"]["failed_checks"])] for c in limits]))
    if not failed and not limits:
        out.append("<p class=good>Every case passed its thresholds.</p>")
    return "\n".join(out)


def sweep_section(sweep):
    analysis = sweep.get("analysis", [])
    if not analysis:
        return ""
    opts = sweep["options"]
    labels = opts["offset_labels"]
    eps_values = sorted(opts["eps"], reverse=True)
    out = [f"<h2 id=sweep>eps &times; offset sweep</h2><p>The {esc(opts['backend'])} backend at {esc(opts['size'])} "
           "over hit thresholds eps and re-entry offsets (multiples of eps, and fixed values), each point judged "
           "against one truth (the oracle, masked as for the default parameters). <b>Stability</b> heatmaps: the "
           "colour is the share of decided pixels whose hit is wrong (mean over the surface type's scenes, log); "
           "a tick marks a stable point (every scene passes the conformance checks but the perceptual one, "
           "which small frames make noisy; a tick on a coloured cell is an error conformance/thresholds.json allows "
           "with its reason, such as sphere tracing running out of steps near the horizon, on up to 2% of the "
           "pixels of several scenes and most of a translation prism's); the star, the recommendation: of the stable points whose "
           "neighbours a decade of eps either side are stable too, one within 10% of the fastest with the most stable "
           "neighbours on the grid. <b>Steps</b> heatmaps: mean kernel steps per "
           "ray. The Pareto chart: each grid point's time against its error; the front joins the points no other "
           "beats on both.</p>"]
    rec_rows = []
    types = [t for t in SURFACE_TYPES if any(g["surface_type"] == t for g in analysis)]
    for t in types:
        groups = [g for g in analysis if g["surface_type"] == t]
        methods = [m for m in METHODS if any(g["method"] == m for g in groups)]
        precisions = [p for p in ["f32", "f64"] if any(g["precision"] == p for g in groups)]
        scenes = sorted({p["scene"] for p in sweep["points"] if p["surface_type"] == t})
        out.append(f"<h3>{esc(t)} surfaces ({esc(', '.join(scenes))})</h3>")
        steps = [c["steps_mean"] for g in groups for c in g["grid"] if not c["errors"] and c["steps_mean"] > 0]
        steps_norm = LogNorm(vmin=max(1, min(steps)), vmax=max(2, max(steps))) if steps else LogNorm(1, 2)
        for what in ("stability", "steps"):
            fig, axes = plt.subplots(len(precisions), len(methods), squeeze=False, layout="constrained",
                                     figsize=(3.6 * len(methods) + 1.2, 3.3 * len(precisions)))
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
                            if c is None or c["errors"]:
                                continue
                            v = 100 * c["hit_mismatch"] if what == "stability" else c["steps_mean"]
                            grid[r][k] = max(v, 1e-3) if what == "stability" else max(v, 1)
                    im = ax.imshow(grid, aspect="auto", cmap="magma_r" if what == "stability" else "viridis",
                                   norm=LogNorm(vmin=1e-3, vmax=100) if what == "stability" else steps_norm)
                    for r, e in enumerate(eps_values):
                        for k, lab in enumerate(labels):
                            c = cells.get((e, lab))
                            if c and what == "stability" and c["stable"]:
                                ax.text(k, r, "\u2713", ha="center", va="center", color="#33ff77", fontsize=11,
                                        fontweight="bold", path_effects=[withStroke(linewidth=2, foreground="black")])
                            if c and what == "steps" and not math.isnan(grid[r][k]):
                                ax.text(k, r, f"{grid[r][k]:.0f}", ha="center", va="center", fontsize=6,
                                        color="white" if grid[r][k] < 40 else "black")
                    rec = g.get("recommended")
                    if rec:
                        ax.plot(labels.index(rec["offset_label"]), eps_values.index(rec["eps"]), marker="*",
                                ms=16, mfc="none", mec="#00bfff", mew=2)
                    ax.set_xticks(range(len(labels)), labels, rotation=60, fontsize=7)
                    ax.set_yticks(range(len(eps_values)), [f"{e:g}" for e in eps_values], fontsize=7)
                    ax.set_title(f"{m}, {prec}", fontsize=9)
                    if j == 0:
                        ax.set_ylabel("eps")
                    if i == len(precisions) - 1:
                        ax.set_xlabel("offset")
            fig.colorbar(im, ax=axes, shrink=0.8,
                         label="hit wrong, % of decided pixels" if what == "stability" else "mean steps per ray")
            out.append(figure_html(fig, f"{what} heatmap, {t}"))
        fig, axes = plt.subplots(1, len(precisions), squeeze=False, figsize=(5.0 * len(precisions), 3.6))
        for i, prec in enumerate(precisions):
            ax = axes[0][i]
            for g in groups:
                if g["precision"] != prec:
                    continue
                col = {"sphere": "#1f77b4", "relaxed": "#ff7f0e", "analytic": "#2ca02c"}[g["method"]]
                pts = [c for c in g["grid"] if not c["errors"]]
                ax.scatter([c["time_ms"] for c in pts], [max(100 * c["hit_mismatch"], 1e-3) for c in pts], s=12,
                           color=col, alpha=0.35)
                front = g["pareto"]
                ax.plot([p["time_ms"] for p in front], [max(100 * p["hit_mismatch"], 1e-3) for p in front],
                        "-o", color=col, ms=4, label=f'{g["method"]} front')
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel("time per frame, ms (log)")
            ax.set_ylabel("hit wrong, % of decided pixels")
            ax.set_title(f"{t}, {prec}: speed against accuracy")
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=7)
        fig.tight_layout()
        out.append(figure_html(fig, f"pareto, {t}"))
        for g in groups:
            r = g.get("recommended")
            rec_rows.append([t, g["method"], g["precision"], f'{len(g["stable"])}/{len(g["grid"])}',
                             f'{r["eps"]:g}' if r else "-", f'{r["offset"]:g} ({r["offset_label"] if r["offset_label"].endswith("xeps") else "fixed"})' if r else "-",
                             (f'{r["time_ms"]:.3g} ms, {pct(r["hit_mismatch"])} wrong' if r else "nothing stable")])
    out.insert(1, table(["surface type", "method", "precision", "stable points", "eps", "offset", "at"], rec_rows))
    return "\n".join(out)


def scaling_section(scaling):
    series = scaling.get("series", [])
    if not series:
        return ""
    axes_names = [("pixels", "pixels per frame"), ("edges", "edges of the surface"),
                  ("max_distance", "path length (max_distance)")]
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.6))
    rows = []
    for ax, (axis, label) in zip(axes, axes_names):
        for s in series:
            if s["axis"] != axis or not s["x"]:
                continue
            style = "-" if "staircase" not in s["family"] else "--"
            ax.plot(s["x"], s["time_ms"], style, marker=METHOD_MARKERS.get(s["method"], "o"), ms=4,
                    color=BACKEND_COLOURS.get(s["backend"], "k"),
                    label=f'{s["backend"]} {s["method"]}{" staircase" if "staircase" in s["family"] else ""}: '
                          f'slope {s["slope"]:.2f}')
            lanes = s.get("lane_utilisation")
            rows.append([axis, s["family"], s["backend"], s["method"], f'{s["slope"]:.2f}', f'{s["steps_slope"]:.2f}',
                         f'{min(s["x"]):g} to {max(s["x"]):g}',
                         f'{s["time_ms"][0]:.3g} to {s["time_ms"][-1]:.3g}',
                         " ".join(pct(v) for v in lanes) if lanes else "-"])
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(label + " (log)")
        ax.set_ylabel("ms per frame (log)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2)
    fig.tight_layout()
    return ("<h2 id=scaling>Scaling</h2><p>Time per frame against pixels (the gallery torus), against the "
            "number of edges (regular 2n-gons, solid; staircases of squares, each its own room, dashed; both "
            "empty translation prisms where every ray runs the same distance) and against the path length "
            "(an empty torus prism, where every ray runs max_distance). The slope is the exponent of a power-law "
            "fit: 1 is linear. The SIMD backend's lanes idle when the rays of a packet are in different rooms: the last "
            "column shows the share of its lanes at work at each point of a series.</p>" + figure_html(fig, "scaling") +
            table(["axis", "family", "backend", "method", "time slope", "steps slope", "x", "ms", "SIMD lanes busy, per point"],
                  rows))


PAGE = """<!doctype html><html><head><meta charset="utf-8"><title>{title}</title><style>
body {{ font-family: sans-serif; margin: 1.5em auto; max-width: 1500px; color: #222; }}
table {{ border-collapse: collapse; margin: 0.6em 0; font-size: 0.85em; }}
th, td {{ border: 1px solid #ccc; padding: 3px 6px; text-align: left; vertical-align: top; }}
th {{ background: #eee; }} td.bad {{ background: #fdd; }} .bad {{ color: #a00; }} .good {{ color: #070; }}
img.chart {{ max-width: 100%; display: block; margin: 0.5em 0; }} img.frame {{ width: 200px; }}
.choice {{ font-size: 1.1em; background: #eef6ff; padding: 0.6em; }} nav a {{ margin-right: 1em; }}
</style></head><body>{body}</body></html>"""


def one_machine(results, images):
    cases = results.get("matrix", {}).get("cases", [])
    body = [f"<h1>flatmarch report</h1><p>Measured {esc(results.get('created'))}: timed frames "
            f"{esc(results['options']['size'])} (median of {results['options']['repetitions']} repetitions, "
            f"Google Benchmark), conformance frames {esc(results['options']['conform_size'])}, eps "
            f"{results['options']['eps']:g}, offset {results['options']['offset']:g}.</p>",
            "<nav>" + "".join(f'<a href="#{a}">{t}</a>' for a, t in [
                ("ranking", "ranking"), ("speed", "speed vs accuracy"), ("gallery", "gallery"), ("steps", "steps"),
                ("failures", "failures"), ("sweep", "eps x offset"), ("scaling", "scaling"), ("machine", "machine")]) +
            "</nav>",
            ranking_section(results), speed_accuracy_section(cases), gallery_section(results, images),
            steps_heatmap_section(cases), failure_section(cases), sweep_section(results.get("sweep", {})),
            scaling_section(results.get("scaling", {})),
            "<h2 id=machine>Machine</h2>" + table(["", ""], fingerprint_rows(results["fingerprint"]))]
    return PAGE.format(title="flatmarch report", body="\n".join(body))


# --- Machines compared.


def gpu_text(fp):
    """The machine's GPU, as its GPU backends found one: ", GPU NAME", or "" without one."""
    for api in ("vulkan", "opengl"):
        d = fp.get(api, {})
        name = d.get("device") or d.get("renderer")
        if name and "software" in d and not d["software"]:
            return f", GPU {name}"
    return ""


def machines(all_results, names):
    body = ["<h1>flatmarch: machines compared</h1>"]
    fps = [r["fingerprint"] for r in all_results]
    rows = []
    for k, (label, _) in enumerate(fingerprint_rows(fps[0])):
        rows.append([label] + [fingerprint_rows(fp)[k][1] for fp in fps])
    body.append(table(["", *names], rows))
    backends = sorted({b["backend"] for r in all_results for b in r.get("ranking", [])})
    fig, ax = plt.subplots(figsize=(2 + 1.6 * len(backends), 4.5))
    width = 0.8 / len(all_results)
    for i, (r, name) in enumerate(zip(all_results, names)):
        ranked = {b["backend"]: b for b in r.get("ranking", [])}
        # A backend a machine did not measure gets no bar (not a zero, which a log axis cannot draw).
        xs = [k + i * width for k, b in enumerate(backends) if ranked.get(b, {}).get("rays_per_s")]
        ys = [ranked[b]["rays_per_s"] / 1e6 for b in backends if ranked.get(b, {}).get("rays_per_s")]
        bars = ax.bar(xs, ys, width, label=name)
        # Each GPU backend's bar names its device: the same backend is a GPU on one machine and
        # a software rasteriser on another.
        for bar, b in zip(bars, [b for b in backends if ranked.get(b, {}).get("rays_per_s")]):
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
    body.append("<h2>Speed per backend</h2>" + figure_html(fig, "speed per machine"))
    rows = []
    for r, name in zip(all_results, names):
        rec = r.get("recommendation", {})
        order = ", ".join(f'{b["rank"]}. {b["backend"]} on {device_text(b)} ({mrays(b["rays_per_s"])}, '
                          f'{b["passed"]}/{b["cases"]})' for b in r.get("ranking", []))
        rows.append([name, f'{rec.get("backend")} / {rec.get("method")}', order])
    body.append("<h2>Rankings</h2>" + table(["machine", "choice", "ranking (Mrays/s, cases conforming)"], rows))
    base = {c["name"]: c for c in all_results[0].get("matrix", {}).get("cases", []) if "time_ms" in c}
    base_devices = {b["backend"]: device_text(b) for b in all_results[0].get("ranking", [])}
    rows = []
    for r, name in zip(all_results[1:], names[1:]):
        ratios = {}
        for c in r.get("matrix", {}).get("cases", []):
            if c["name"] in base and "time_ms" in c:
                ratios.setdefault(c["backend"], []).append(base[c["name"]]["time_ms"] / c["time_ms"])
        devices = {b["backend"]: device_text(b) for b in r.get("ranking", [])}
        for b, v in sorted(ratios.items()):
            g = math.exp(sum(math.log(x) for x in v) / len(v))
            rows.append([name, b, base_devices.get(b, "?"), devices.get(b, "?"), len(v), f"{g:.3g}x",
                         f"{min(v):.3g}x", f"{max(v):.3g}x"])
    if rows:
        body.append(f"<h2>Speed-up over {esc(names[0])}</h2><p>Per backend, over the cases both measured: the "
                    "geometric mean, least and greatest ratio of frame times (above 1: faster than the first "
                    "machine), with the device each machine's backend ran on.</p>" +
                    table(["machine", "backend", "device there", "device here", "cases", "geometric mean",
                           "least", "greatest"], rows))
    return PAGE.format(title="flatmarch: machines compared", body="\n".join(body))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("results", nargs="+", help="results.json files of flatmarch report")
    parser.add_argument("-o", "--out", required=True, help="output folder")
    args = parser.parse_args()
    all_results = []
    for path in args.results:
        with open(path) as f:
            all_results.append(json.load(f))
    os.makedirs(args.out, exist_ok=True)
    use_registry(all_results)
    if len(all_results) == 1:
        images = os.path.join(os.path.dirname(os.path.abspath(args.results[0])), "images")
        page = one_machine(all_results[0], images)
    else:
        names = [f'{os.path.basename(os.path.dirname(os.path.abspath(p))) or p}: '
                 f'{r["fingerprint"]["cpu"]["model"]}{gpu_text(r["fingerprint"])}'
                 for p, r in zip(args.results, all_results)]
        page = machines(all_results, names)
    with open(os.path.join(args.out, "index.html"), "w") as f:
        f.write(page)
    return 0


if __name__ == "__main__":
    sys.exit(main())
