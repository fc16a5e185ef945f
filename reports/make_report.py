#!/usr/bin/env python3
"""The report's page: charts (matplotlib) and tables from the results files of `flatmarch report`.

    make_report.py -o OUT RESULTS.json            one machine: OUT/index.html
    make_report.py -o OUT --previous OLD.json RESULTS.json
                                                  the same, with the change per case since OLD
    make_report.py -o OUT A.json B.json ...       machines compared: OUT/index.html

The page is self-contained: charts and gallery images are embedded (PNG, base64). Its words and
layout are the template page.html.j2 beside this script (Jinja); this script draws the charts and
the tables and hands them to it. Called by `flatmarch report`; runs on Debian's python3 with
python3-matplotlib and python3-jinja2.
"""
import argparse
import base64
import html
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

# The kernel's backends and methods, in the order flatmarch lists them: read from the results'
# "registry" (use_registry), never restated here. Each gets a colour or marker by its place.
METHODS = []
BACKEND_COLOURS = {}
METHOD_MARKERS = {}
PALETTE = ["#1f77b4", "#2ca02c", "#d62728", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf"]
MARKERS = ["o", "s", "^", "D", "v", "P"]
SURFACE_TYPES = []
# The suite's words (conformance/vocabulary.hpp), read from the results' "vocabulary"
# (use_vocabulary), never restated here: the pixel and failure classes with their colours, the
# checks, the other causes of an unstable sweep point, the verdicts and the ambiguity goals.
VOCABULARY = {}
FAILURE_MEANINGS = {}  # failure class -> what it means, in compare.hpp's order
FAILURES = []
CHECKS = {}  # check -> what it measures
CHECK_PREFIXES = {}  # checks named per region of the frame ("colour.object 0"), by their prefix
CAUSE_CODES = {}  # the short code each cause of an unstable sweep point gets in its heatmap cell
CAUSE_MEANINGS = {}
VERDICTS = {}  # a case's verdict -> what it means
UNFINISHED = ()  # the verdicts of a supervised run's cases that did not finish
BAD = ()  # counted against a backend: fail, error and the unfinished


def use_vocabulary(all_results):
    """Takes the suite's words from the first results that carry them."""
    vocabulary = next((r["vocabulary"] for r in all_results if "vocabulary" in r), None)
    if vocabulary is None:
        sys.exit("make_report.py: none of the results files has a \"vocabulary\": they were written "
                 "by an older flatmarch; run the report again")
    global UNFINISHED, BAD
    VOCABULARY.clear()
    VOCABULARY.update(vocabulary)
    failures = [c for c in vocabulary["pixel_classes"] if c["failure"]]
    FAILURE_MEANINGS.clear()
    FAILURE_MEANINGS.update({c["name"]: c["meaning"] for c in failures})
    FAILURES[:] = list(FAILURE_MEANINGS)
    CHECKS.clear()
    CHECKS.update({c["name"]: c["meaning"] for c in vocabulary["checks"]})
    CHECK_PREFIXES.clear()
    CHECK_PREFIXES.update({c["prefix"]: c["meaning"] for c in vocabulary["check_prefixes"]})
    causes = failures + vocabulary["checks"] + vocabulary["other_causes"]
    CAUSE_CODES.clear()
    CAUSE_CODES.update({c["name"]: c["code"] for c in causes if c["code"]})
    CAUSE_MEANINGS.clear()
    CAUSE_MEANINGS.update({c["name"]: c["meaning"] for c in causes})
    VERDICTS.clear()
    VERDICTS.update({v["name"]: v["meaning"] for v in vocabulary["verdicts"]})
    UNFINISHED = tuple(v["name"] for v in vocabulary["verdicts"] if v["unfinished"])
    BAD = tuple(v["name"] for v in vocabulary["verdicts"] if v["bad"])


def use_registry(all_results):
    """Takes the backend, method and surface type lists from the results (the first that carries
    them; results written before they did: the backends and methods their cases name, in order of
    appearance, and the surface types of their cases and sweep)."""
    backends, methods, types = [], [], []
    for r in all_results:
        if "registry" in r:
            backends, methods = r["registry"]["backends"], r["registry"]["methods"]
            types = r["registry"].get("surface_types", [])
            break
    if not types:
        for r in all_results:
            for c in r.get("matrix", {}).get("cases", []) + r.get("sweep", {}).get("analysis", []):
                if c["surface_type"] not in types:
                    types.append(c["surface_type"])
    if not backends:
        for r in all_results:
            for c in r.get("matrix", {}).get("cases", []):
                if c["backend"] not in backends:
                    backends.append(c["backend"])
                if c["method"] not in methods:
                    methods.append(c["method"])
    METHODS[:] = methods
    SURFACE_TYPES[:] = types
    BACKEND_COLOURS.clear()
    BACKEND_COLOURS.update({b: PALETTE[k % len(PALETTE)] for k, b in enumerate(backends)})
    METHOD_MARKERS.clear()
    METHOD_MARKERS.update({m: MARKERS[k % len(MARKERS)] for k, m in enumerate(methods)})


def esc(text):
    return html.escape(str(text))


def html_(text):
    """Text that is HTML already (a table, a chart), for the template to take as it is."""
    return markupsafe.Markup(text)


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


def verdict(case):
    """A case's verdict: pass, limit, fail, or error (results written before verdicts: pass or
    fail by its checks); None for a case not measured against the oracle."""
    if case.get("verdict") in UNFINISHED:
        return case["verdict"]
    if "error" in case:
        return "error"
    a = case.get("accuracy")
    if not a:
        return None
    return a.get("verdict", "pass" if a["passed"] else "fail")


def verdict_html(v):
    return f'<span class="verdict {esc(v)}">{esc(v)}</span>'


def reason_html(line):
    """One failed check ("name value < limit") with what the check measures."""
    name = line.split(" ", 1)[0]
    what = CHECKS.get(name) or next((v for k, v in CHECK_PREFIXES.items() if line.startswith(k)), None)
    return f"<code>{esc(line)}</code>" + (f": {esc(what)}" if what else "")


def device_text(backend):
    """Where a ranked backend ran: its GPU-backend device (marked when software), or the CPU."""
    d = backend.get("device")
    if not d:
        return "CPU"
    return d["name"] + (" (software)" if d.get("software") else "") + (f', {d["driver"]}' if d.get("driver") else "")


def fingerprint_rows(results):
    """The machine table's rows, as the run wrote them (its registry's fingerprint_rows: the CPU,
    what each backend says of the machine, the OS, the libraries, the build); a run written
    before they were has its CPU and OS alone."""
    rows = results.get("registry", {}).get("fingerprint_rows")
    if rows is not None:
        return [tuple(r) for r in rows]
    fp = results.get("fingerprint", {})
    cpu = fp.get("cpu", {})
    return [("CPU", f'{cpu.get("model", "?")}, {cpu.get("logical_cores", "?")} threads'),
            ("OS", f'{fp.get("os", "?")} on {fp.get("host", "?")}')]


# --- One machine.


def summary_section(results, cases):
    """The verdicts counted apart, overall and per backend and method."""
    counts = {v: 0 for v in VERDICTS}
    per = {}
    for c in cases:
        v = verdict(c)
        if v is None:
            continue
        counts[v] += 1
        per.setdefault(c["backend"], {}).setdefault(c["method"], {k: 0 for k in VERDICTS})[v] += 1
    shown = [v for v in VERDICTS if v not in ("error",) + UNFINISHED or counts[v]]
    rows = []
    for b, methods in per.items():
        row = [b]
        for m in METHODS:
            n = methods.get(m)
            row.append(td(" · ".join(f"{n[v]} {v}" for v in VERDICTS
                                     if n[v] or v not in ("error",) + UNFINISHED) if n else "-",
                          "bad" if n and any(n[v] for v in BAD) else "limit" if n and n["limit"] else ""))
        rows.append(row)
    meanings = [(v, m) for v, m in VERDICTS.items() if v not in UNFINISHED or counts[v]]
    return PAGE.summary(results, counts, shown, meanings, html_(table(["backend"] + METHODS, rows)))


def definitions_section(results, cases):
    prisms = sorted({c["scene"] for c in cases if c["surface_type"] == "prism"})
    check_rows = [[f"<td><code>{esc(k)}</code></td>", v] for k, v in CHECKS.items()]
    check_rows += [[f"<td><code>{esc(k)}REGION</code></td>", v] for k, v in CHECK_PREFIXES.items()]
    return PAGE.definitions(results, prisms, html_(table(["failure class", "the ray"], FAILURE_MEANINGS.items())),
                            html_(table(["check", "measures"], check_rows)))


def ambiguity_section(cases):
    """The ambiguous share per scene and method, from the first backend (in the registry's order)
    that measured the pair; a backend that found another share is named in the cell."""
    shares = {}
    for c in cases:
        if "accuracy" in c and "ambiguous" in c["accuracy"]:
            shares.setdefault((c["scene"], c["method"]), []).append((c["backend"], c["accuracy"]["ambiguous"]))
    if not shares:
        return ""
    order = list(BACKEND_COLOURS)
    scenes = []
    for c in cases:
        if c["scene"] not in scenes:
            scenes.append(c["scene"])
    types = {c["scene"]: c["surface_type"] for c in cases}
    methods = [m for m in METHODS if any(k[1] == m for k in shares)]
    first_backends = set()
    rows = []
    for s in scenes:
        row = [s, types[s]]
        for m in methods:
            got = sorted(shares.get((s, m), []), key=lambda bv: order.index(bv[0]) if bv[0] in order else len(order))
            if not got:
                row.append("-")
                continue
            first_backends.add(got[0][0])
            others = [f"{b} {pct(v)}" for b, v in got[1:] if abs(v - got[0][1]) > 1e-9]
            goal = VOCABULARY["ambiguity_goals"].get(m, {}).get("prism" if types[s] == "prism" else "other")
            cls = "warn" if goal is not None and got[0][1] > goal else ""
            row.append(td(pct(got[0][1]) + (f" (other: {', '.join(others)})" if others else ""), cls))
        rows.append(row)
    means = ["mean over these scenes", ""]
    for m in methods:
        v = [sorted(shares[(s, m)], key=lambda bv: order.index(bv[0]) if bv[0] in order else len(order))[0][1]
             for s in scenes if (s, m) in shares]
        means.append(pct(sum(v) / len(v)) if v else "-")
    rows.append(means)
    return PAGE.ambiguity(sorted(first_backends), html_(table(["scene", "surface type"] + methods, rows)))


def ranking_section(results):
    rec = results.get("recommendation", {})
    rows = []
    for t, p in rec.get("parameters", {}).items() if rec.get("backend") else []:
        if p["source"] == "sweep":
            src = "the sweep's recommendation" + (", re-checked at " + p["confirmed"]["size"]
                                                  if p.get("confirmed") else "")
            if p.get("fallback"):
                src = "<b>fallback</b>: " + src + ", a stable point none of whose eps neighbours is stable"
        else:
            src = (f'<b>fallback</b>, the defaults: no point of the sweep passes with {esc(rec["method"])} on '
                   f'every {esc(t)} scene')
            stable = p.get("stable_methods", [])
            src += ("; stable there, use instead: " + ", ".join(
                f'<b>{esc(m["method"])}</b> (eps {m["eps"]:g}, offset {m["offset"]:g})' for m in stable)
                    if stable else "; no method is stable there")
        rows.append((t, f'{p["eps"]:g}', f'{p["offset"]:g}',
                     f'<td class="{"limit" if p.get("fallback") else ""}">{src}</td>'))
    parameters = html_(table(["surface type", "eps", "offset", "from"], rows)) if rows else ""
    methods = METHODS
    rows = []
    for b in results.get("ranking", []):
        row = [b["rank"], b["backend"], device_text(b), mrays(b["rays_per_s"]),
               f'{b["passed"]}/{b["cases"]} pass' + (f', {b["limits"]} limit' if b.get("limits") else "")
               + (f', {b["errors"]} errors' if b["errors"] else "")
               + (f'; a sample: {b["sampled"]["cases"]} of {b["sampled"]["of_cases"]} cases'
                  if b.get("sampled") else "")]
        for m in methods:
            mm = b["methods"].get(m)
            peak = f', {pct(mm["of_peak"])} of peak' if mm and "of_peak" in mm else ""
            if mm and "lane_efficiency" in mm:
                peak += f', {pct(mm["lane_efficiency"])} of its lanes'
            row.append(f'{mrays(mm["rays_per_s"])} ({int(mm["passed"])}/{int(mm["cases"])} pass{peak})'
                       if mm else "-")
        row.append(b["best_method"] or "-")
        rows.append(row)
    ranked = table(["rank", "backend", "device", "Mrays/s", "verdicts"] + [f"{m} Mrays/s" for m in methods] +
                   ["fastest conforming method"], rows)
    return PAGE.ranking(results, rec, parameters, html_(ranked))


def device_time_section(results, cases):
    """Each GPU backend's frames split by the device's own clock: the march, the read-back, the rest."""
    ranked = [b for b in results.get("ranking", []) if b.get("device_time")]
    missing = sorted({c["backend"] for c in cases if c.get("device") and
                      not c.get("counters", {}).get("device_ms")})
    if not ranked and not missing:
        return ""
    rows = []
    for b in ranked:
        d = b["device_time"]
        shape = b.get("device", {}).get("kernel_shape", "")
        rows.append([b["backend"], device_text(b), shape or "-", d["cases"], f'{d["wall_ms"]:.3g}',
                     f'{d["device_ms"]:.3g}', pct(d["march_share"]), pct(d["readback_share"]),
                     pct(d["rest_share"])])
    figure = ""
    if rows:
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
        figure = figure_html(fig, "each GPU backend's frame split by the device's clock")
    return PAGE.device_time(html_(table(["backend", "device", "kernel shape", "cases", "wall ms", "device ms",
                                         "march", "read-back", "rest"], rows)) if rows else "",
                            html_(figure), missing)


def left_out_note(results):
    """What a run measured without the image library left out, and how to draw it."""
    left = results.get("left_out")
    if not left:
        return ""
    what = ", ".join("Yee's perceptual check" if w == "image.perceptual_failpercent" else
                     "each backend's frames and the recommended gallery" for w in left.get("what", []))
    return PAGE.left_out(left, what)


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
            v = verdict(c)
            colour = BACKEND_COLOURS.get(c["backend"], "k")
            ax.scatter(c["counters"]["rays_per_s"] / 1e6, max(y, 1e-3), s=36,
                       marker=METHOD_MARKERS.get(c["method"], "o"),
                       facecolors=colour if v == "pass" else "none", edgecolors=colour, linewidths=1.3,
                       linestyle="-" if v != "limit" else (0, (1.5, 1)))
            if v == "fail":
                ax.scatter(c["counters"]["rays_per_s"] / 1e6, max(y, 1e-3), s=36, marker="x", color=colour,
                           linewidths=1.0)
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
    handles += [plt.Line2D([], [], color="k", marker="o", mfc="none", ls="", label="limit (hollow)"),
                plt.Line2D([], [], color="k", marker="x", ls="", label="fail (crossed)")]
    fig.legend(handles=handles, loc="upper center", ncol=8, bbox_to_anchor=(0.5, 0.0))
    fig.tight_layout()
    return PAGE.speed_accuracy(html_(figure_html(fig, "speed against accuracy")))


def gallery_section(results, images):
    scenes = results["options"]["scenes"]
    backends = ["oracle"] + [b["backend"] for b in results.get("ranking", [])]
    cases = results.get("matrix", {}).get("cases", [])
    # The matrix keeps the frames of the first method it measured.
    method = cases[0]["method"] if cases else "?"
    verdicts = {(c["backend"], c["scene"]): verdict(c) for c in cases if c["method"] == method}
    rows = []
    for s in scenes:
        cells = [f"<td>{esc(s)}</td>"]
        for b in backends:
            v = verdicts.get((b, s))
            cells.append("<td>" + image_html(os.path.join(images, b, s + ".png"), f"{s}, {b}")
                         + (f"<br>{verdict_html(v)}" if v else "") + "</td>")
        rows.append(cells)
    return PAGE.gallery(results, method, html_(table(["scene"] + backends, rows, "gallery")))


def recommended_gallery_section(results, images):
    g = results.get("gallery")
    if not g:
        why = ("no backend passed every case of any method here, so nothing is recommended"
               if not results.get("recommendation", {}).get("backend") else "these results have no gallery")
        return PAGE.recommended(g, why, {}, [], "")
    legend = [e for e in VOCABULARY["pixel_classes"] if e["name"] != "agree" and not e["traces_only"]]
    colour_name = {e["name"]: e["colour_name"] for e in VOCABULARY["pixel_classes"]}
    rows = []
    for sc in g["scenes"]:
        oracle = image_html(os.path.join(images, "oracle", sc["scene"] + ".png"), f'{sc["scene"]}, oracle')
        if "error" in sc:
            rows.append([sc["scene"], f"<td>{oracle}</td>", f'<td class="bad">{esc(sc["error"])}</td>', "-", "-"])
            continue
        counts = sc["counts"]
        pixels = sc["pixels"]
        decided = pixels - counts.get("ambiguous", 0)
        differ = [f'{esc(k)} {pct(n / pixels)}' for k, n in counts.items() if n and k not in ("agree",)]
        wrong = decided - counts.get("agree", 0)
        rows.append([sc["scene"], f"<td>{oracle}</td>",
                     "<td>" + image_html(os.path.join(images, sc["image"]),
                                         f'{sc["scene"]}, {g["backend"]} {g["method"]}') + "</td>",
                     "<td>" + image_html(os.path.join(images, sc["diff"]), f'{sc["scene"]}, difference') + "</td>",
                     f'<td>eps {sc["eps"]:g}, offset {sc["offset"]:g}<br>'
                     f'{pct(wrong / decided) if decided else "-"} of the decided pixels differ<br>'
                     f'<small>{"; ".join(differ) or "no pixel differs"} (of all {pixels})</small></td>'])
    return PAGE.recommended(g, "", colour_name, legend, html_(table(
        ["scene", "oracle", f'{g["backend"]}, {g["method"]}', "difference", "parameters and pixels"], rows,
        "gallery recommended")))


def number(v):
    return f"{v:.4g}" if isinstance(v, float) else esc(v)


def regression_section(results):
    """The regression gate's verdict on this run's figures (results["regression"], written by
    `flatmarch report`)."""
    r = results.get("regression")
    if not r or not r["checked"]:
        return PAGE.regression(r, "", "", "", "")

    def rows_of(entries):
        rows = []
        for g in entries:
            was, now = g["was"], g["now"]
            change = f"{now - was:+.4g}" if isinstance(was, (int, float)) and isinstance(now, (int, float)) \
                and not isinstance(was, bool) else "-"
            extra = "<br>".join(reason_html(x) for x in g.get("failed_checks", []))
            rows.append([g["case"], g["figure"], number(was), number(now), change,
                         number(g["tolerance"]) if "tolerance" in g else "-", f"<td>{extra}</td>"])
        return rows
    header = ["case", "figure", "baseline", "now", "change", "tolerance", "failed checks now"]
    source = ("the baseline given with --baseline" if r.get("given")
              else "the committed baseline, as this run was measured alike")
    warnings = table(["case", "baseline ms", "now ms", "ratio", "p"],
                     [[w["case"], f'{w["was_ms"]:.3g}', f'{w["now_ms"]:.3g}', f'{w["ratio"]:.2f}',
                       f'{w["p_value"]:.2g}'] for w in r["timing_warnings"]])
    return PAGE.regression(r, source, html_(table(header, rows_of(r["regressions"]), "regressions"))
                           if r["regressions"] else "",
                           html_(table(header, rows_of(r["improvements"]))) if r["improvements"] else "",
                           html_(warnings) if r["timing_warnings"] else "")


def previous_section(results, previous, previous_path):
    """The change per case since an earlier run: verdict changes first, then the figures."""
    if previous is None:
        return ""
    # Cases by backend, method and scene: the case name also carries the timed frame size.
    def key(c):
        return c["backend"], c["method"], c["scene"]
    now = {key(c): c for c in results.get("matrix", {}).get("cases", [])}
    was = {key(c): c for c in previous.get("matrix", {}).get("cases", [])}
    common = [k for k in now if k in was]
    sizes = [(r.get("options", {}).get("size"), r.get("options", {}).get("conform_size")) for r in (previous, results)]
    # Worse the later in the vocabulary's order (pass, limit, fail, error, then the unfinished).
    rank = {v: k for k, v in enumerate(VERDICTS)} | {None: -1}
    changed = [(n, verdict(was[n]), verdict(now[n])) for n in common if verdict(was[n]) != verdict(now[n])]
    changed.sort(key=lambda x: (rank[x[1]] >= rank[x[2]], x[0]))  # worse first
    if changed:
        rows = []
        for n, before, after in changed:
            a = now[n].get("accuracy", {})
            why = "<br>".join(reason_html(x) for x in a.get("failed_checks", [])) or esc(now[n].get("error", ""))
            rows.append([now[n]["name"], f"<td>{verdict_html(before or 'not judged')}</td>",
                         f"<td>{verdict_html(after or 'not judged')}</td>",
                         "worse" if rank[after] > rank[before] else "better", f"<td>{why}</td>"])
    changed = table(["case", "before", "now", "", "failed checks now"], rows, "reasons") if changed else ""
    same_cpu = previous.get("fingerprint", {}).get("cpu") == results.get("fingerprint", {}).get("cpu")
    rows = []
    for n in common:
        a, b = was[n].get("accuracy"), now[n].get("accuracy")
        d_hit = d_amb = None
        if a and b:
            d_hit = b["hit_mismatch"] - a["hit_mismatch"]
            d_amb = b.get("ambiguous", 0.0) - a.get("ambiguous", 0.0)
        ra, rb = was[n].get("counters", {}).get("rays_per_s"), now[n].get("counters", {}).get("rays_per_s")
        speed = rb / ra if ra and rb else None
        if (d_hit is not None and abs(d_hit) > 1e-4) or (d_amb is not None and abs(d_amb) > 1e-4) or \
                (speed is not None and not 0.9 <= speed <= 1.1):
            rows.append((n, d_hit, d_amb, speed))
    rows.sort(key=lambda x: (-abs(x[1] or 0), -abs(x[2] or 0), -abs(math.log(x[3])) if x[3] else 0))

    def delta(v):
        if v is None:
            return "-"
        if abs(v) < 5e-6:
            return "0"
        return td(f"{100 * v:+.3g} pp", "bad" if v > 1e-4 else "good" if v < -1e-4 else "")
    figures = table(["case", "hit wrong", "ambiguous", "speed"],
                    [[now[n]["name"], delta(h), delta(a), f"{s:.3g}x" if s else "-"] for n, h, a, s in rows]) \
        if rows else ""
    return PAGE.previous(previous, previous_path, len(common), len(now) - len(common), len(was) - len(common),
                         sizes, html_(changed), html_(figures), same_cpu)


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
    scalar = {(c["scene"], c["method"]): c["counters"].get("rays_per_s", 0) for c in cases
              if c.get("backend") == "scalar" and "counters" in c}
    lane_table = ""
    if simd:
        methods = [m for m in METHODS if any(k[1] == m for k in simd)]

        def efficiency(key, counters):
            """lane_efficiency of reports/report.hpp, or None."""
            one = counters.get("one_thread_rays_per_s", counters.get("rays_per_s", 0))
            lanes, base = counters.get("lanes", 0), scalar.get(key, 0)
            return one / base / lanes if lanes and base and one else None

        def cell(key):
            counters = simd[key]
            text = pct(counters["lane_utilisation"]) + " lanes"
            if "of_peak" in counters:
                text += f' · {pct(counters["of_peak"])} of peak'
            e = efficiency(key, counters)
            if e is not None:
                text += f' · {pct(e)} of {int(counters["lanes"])} lanes'
            return text
        lane_table = table(["scene"] + methods,
                           [[s] + [cell((s, m)) if (s, m) in simd else "-" for m in methods] for s in scenes])
    return PAGE.steps(html_(figure_html(fig, "steps heatmap")), html_(lane_table))


def unfinished_section(results):
    """The cases of a supervised run that did not finish (matrix cases, sweep groups, scaling
    series): what ended each, and the end of what its worker wrote on its standard error."""
    unfinished = results.get("unfinished", [])
    if not unfinished:
        return ""
    rows = []
    for u in unfinished:
        tail = [line for line in u.get("stderr_tail", "").splitlines() if line.strip()][-6:]
        rows.append([u["key"], f"<td>{verdict_html(u['verdict'])}</td>", u["error"],
                     "<td><pre>" + esc("\n".join(tail)) + "</pre></td>" if tail else "-"])
    return PAGE.unfinished(html_(table(["case", "verdict", "what ended it", "its worker's last words"], rows)))


def failure_section(cases):
    rows = []
    totals = {}
    for c in cases:
        key = (c["backend"], c["method"])
        t = totals.setdefault(key, {f: 0 for f in FAILURES} | {v: 0 for v in VERDICTS} | {"cases": 0})
        t["cases"] += 1
        v = verdict(c)
        if v is None:
            continue
        t[v] += 1
        for f in FAILURES:
            t[f] += c.get("accuracy", {}).get("failures", {}).get(f, 0)
    for (b, m), t in sorted(totals.items()):
        rows.append([b, m, t["cases"], t["pass"], td(t["limit"], "limit" if t["limit"] else ""),
                     td(sum(t[v] for v in BAD), "bad" if any(t[v] for v in BAD) else "")] +
                    [td(t[f], "bad" if t[f] else "") for f in FAILURES])
    totals_table = table(["backend", "method", "cases", "pass", "limit", "fail, error or unfinished"] + FAILURES,
                         rows)
    order = {v: 0 for v in BAD} | {"limit": 1}
    bad = sorted((c for c in cases if verdict(c) in order),
                 key=lambda c: (order[verdict(c)], c["scene"], c["method"], c["backend"]))
    # Cases whose verdict and reasons read alike (the same scene and method on several backends)
    # share a row that names each of them.
    groups = {}
    for c in bad:
        v = verdict(c)
        if v == "error" or v in UNFINISHED:
            lines = [esc(c["error"])]
        else:
            a = c["accuracy"]
            lines = [reason_html(line) for line in a.get("failed_checks", [])]
            if v == "limit":
                lines.insert(0, f'<b>{esc(a.get("limit", ""))}</b>')
        groups.setdefault((c["scene"], c["method"], v, tuple(lines)), []).append(c)
    rows = []
    for (scene, method, v, lines), group in groups.items():
        names = " ".join(c["name"] for c in group)
        rows.append([f'<td data-cases="{esc(names)}">{esc(scene)} &middot; {esc(method)}<br>'
                     f'<small>{esc(", ".join(c["backend"] for c in group))} ({esc(group[0]["name"].split("/")[-1])})'
                     "</small></td>", f"<td>{verdict_html(v)}</td>", "<td>" + "<br>".join(lines) + "</td>"])
    reasons = table(["scene · method (backends)", "verdict", "why: each failed check"], rows, "reasons") \
        if rows else ""
    return PAGE.failures(html_(totals_table), html_(reasons))


def sweep_section(sweep):
    analysis = sweep.get("analysis", [])
    if not analysis:
        return ""
    opts = sweep["options"]
    labels = opts["offset_labels"]
    eps_values = sorted(opts["eps"], reverse=True)
    codes = sorted({c.get("cause", "") for g in analysis for c in g["grid"] if not c["stable"]} - {""},
                   key=lambda k: list(CAUSE_CODES).index(k) if k in CAUSE_CODES else len(CAUSE_CODES))
    legend = table(["code", "what made the point unstable"],
                   [[f"<td><b>{esc(CAUSE_CODES.get(k, k[:3]))}</b></td>", f"{k}: {CAUSE_MEANINGS.get(k, '')}"]
                    for k in codes])
    out = []
    rec_rows = []
    no_stable = {}  # (surface type, method, why) -> the precisions with no stable point
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
                            elif c and what == "stability":
                                cause = c.get("cause", "")
                                at_limit = c.get("limits", 0) > 0 and \
                                    c.get("limits", 0) == c["scenes"] - c["passed"] - c["errors"]
                                ax.text(k, r, CAUSE_CODES.get(cause, cause[:3]), ha="center", va="center",
                                        fontsize=7.5, color="#ffd700" if at_limit else "white",
                                        path_effects=[withStroke(linewidth=1.6, foreground="black")])
                            if c and what == "steps" and not math.isnan(grid[r][k]):
                                ax.text(k, r, f"{grid[r][k]:.0f}", ha="center", va="center", fontsize=6,
                                        color="white" if grid[r][k] < 40 else "black")
                    rec = g.get("recommended")
                    if rec:
                        ax.plot(labels.index(rec["offset_label"]), eps_values.index(rec["eps"]), marker="*",
                                ms=16, mfc="none", mec="#ff8c00" if rec.get("fallback") else "#00bfff", mew=2)
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
        stable_methods = {g["precision"]: [] for g in groups}
        for g in groups:
            if g.get("recommended"):
                stable_methods[g["precision"]].append(g["method"])
        for g in groups:
            r = g.get("recommended")
            if r:
                k = r.get("confirmed")
                check = (f'passes at {esc(k["size"])} on {len(k["scenes"])} scene(s)' if k else
                         "not re-checked")
                note = "<b>fallback</b>: no stable eps neighbour" if r.get("fallback") else ""
                rule = r["offset_label"] if r["offset_label"].endswith("xeps") else "fixed"
                rec_rows.append([t, g["method"], g["precision"], f'{len(g["stable"])}/{len(g["grid"])}',
                                 f'{r["eps"]:g}', f'{r["offset"]:g} ({rule})',
                                 f'{r["time_ms"]:.3g} ms, {pct(r["hit_mismatch"])} hit wrong', check,
                                 f'<td class="{"limit" if note else ""}">{note}</td>'])
                continue
            others = [m for m in stable_methods[g["precision"]] if m != g["method"]]
            causes = {}
            for c in g["grid"]:
                if c.get("cause"):
                    causes[c["cause"]] = causes.get(c["cause"], 0) + 1
            top = max(causes, key=causes.get) if causes else None
            advice = (f'use <b>{esc(others[0])}</b>, which is stable here' + (
                f' (or {esc(", ".join(others[1:]))})' if others[1:] else "") if others
                else "no method is stable here")
            rec_rows.append([t, g["method"], g["precision"], f'0/{len(g["grid"])}', "-", "-",
                             f'<td class="bad">nothing stable{f": mostly {esc(top)}" if top else ""}</td>', "-",
                             f"<td>{advice}</td>"])
            why = f'no point of the grid passes on every scene{f" (most often: {esc(top)})" if top else ""}; ' + advice
            no_stable.setdefault((t, g["method"], html_(why)), []).append(g["precision"])
    recommendations = table(["surface type", "method", "precision", "stable points", "eps", "offset", "at",
                             "re-check", "note"], rec_rows)
    return PAGE.sweep(opts, html_(recommendations), no_stable, html_(legend), html_("\n".join(out)))


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
    return PAGE.scaling(html_(figure_html(fig, "scaling")), html_(table(
        ["axis", "family", "backend", "method", "time slope", "steps slope", "x", "ms", "SIMD lanes busy, per point"],
        rows)))


# The page's template, beside this script (a link to it in the build tree, installed beside it).
_TEMPLATES = jinja2.Environment(
    loader=jinja2.FileSystemLoader(os.path.dirname(os.path.abspath(__file__))), autoescape=True,
    undefined=jinja2.StrictUndefined, trim_blocks=True, lstrip_blocks=True)
_TEMPLATES.filters["verdict"] = lambda v: html_(verdict_html(v))
_TEMPLATES.filters["mrays"] = lambda v: mrays(v)
PAGE = _TEMPLATES.get_template("page.html.j2").module


# The sections a forked worker draws: (function, arguments) by index, set before the pool forks.
_SECTION_CALLS = []


def _draw_section(index):
    function, arguments = _SECTION_CALLS[index]
    return function(*arguments)


def draw_sections(calls):
    """Each (function, arguments) called, on every core at once where there are several (the
    charts are most of the page's time: 12 s of a 2-core machine's report on one)."""
    global _SECTION_CALLS
    workers = min(len(calls), len(os.sched_getaffinity(0)))
    if workers < 2 or "fork" not in multiprocessing.get_all_start_methods():
        return [function(*arguments) for function, arguments in calls]
    _SECTION_CALLS = calls
    with multiprocessing.get_context("fork").Pool(workers) as pool:
        return pool.map(_draw_section, range(len(calls)), chunksize=1)


def one_machine(results, images, previous=None, previous_path=""):
    cases = results.get("matrix", {}).get("cases", [])
    named = [("summary", "verdicts", summary_section, (results, cases)),
             ("ranking", "ranking", ranking_section, (results,)),
             ("device", "device time", device_time_section, (results, cases)),
             ("recommended", "recommended choice", recommended_gallery_section, (results, images)),
             ("regression", "regression gate", regression_section, (results,)),
             ("previous", "since the earlier run", previous_section, (results, previous, previous_path)),
             ("failures", "failures", failure_section, (cases,)),
             ("unfinished", "unfinished", unfinished_section, (results,)),
             ("ambiguity", "ambiguity", ambiguity_section, (cases,)),
             ("speed", "speed vs accuracy", speed_accuracy_section, (cases,)),
             ("gallery", "gallery", gallery_section, (results, images)),
             ("steps", "steps", steps_heatmap_section, (cases,)),
             ("sweep", "eps x offset", sweep_section, (results.get("sweep", {}),)),
             ("scaling", "scaling", scaling_section, (results.get("scaling", {}),)),
             ("definitions", "definitions", definitions_section, (results, cases)),
             ("machine", "machine", machine_section, (results,))]
    drawn = draw_sections([(function, arguments) for _, _, function, arguments in named])
    sections = [(anchor, title, text) for (anchor, title, _, _), text in zip(named, drawn)]
    body = [PAGE.header(results), shards_note(results), left_out_note(results),
            "<nav>" + "".join(f'<a href="#{a}">{t}</a>' for a, t, text in sections if text) + "</nav>"]
    body += [text for _, _, text in sections if text]
    return PAGE.page("flatmarch report", html_("\n".join(body)))


def machine_section(results):
    return "<h2 id=machine>Machine</h2>" + table(["", ""], fingerprint_rows(results))


def shards_note(results):
    """Where a merged run's shards ran, and each one's time against the estimate it began with."""
    shards = results.get("shards")
    if not shards:
        return ""
    hosts = ", ".join(h for h in results.get("hosts", []) if h) or "one host"
    rows = [[str(k + 1), s.get("host", ""), f"{sum(s.get('seconds', {}).values()):.0f} s",
             f"{s.get('expected_seconds', 0):.0f} s"] for k, s in enumerate(shards)]
    return PAGE.shards(results, hosts, html_(table(["shard", "host", "measured", "estimated"], rows)))


# --- Machines compared.


def gpu_text(fp):
    """The machine's GPU, as its GPU backends found one (a device of theirs in the fingerprint
    that is not software): ", GPU NAME", or "" without one."""
    for d in fp.values():
        if not isinstance(d, dict):
            continue
        name = d.get("device") or d.get("renderer")
        if isinstance(name, str) and "software" in d and not d["software"]:
            return f", GPU {name}"
    return ""


def machines(all_results, names):
    each = [dict(fingerprint_rows(r)) for r in all_results]
    rows = [[label] + [e.get(label, "") for e in each] for label, _ in fingerprint_rows(all_results[0])]
    machine_table = table(["", *names], rows)
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
    speed = figure_html(fig, "speed per machine")
    rows = []
    for r, name in zip(all_results, names):
        rec = r.get("recommendation", {})
        order = ", ".join(f'{b["rank"]}. {b["backend"]} on {device_text(b)} ({mrays(b["rays_per_s"])}, '
                          f'{b["passed"]}/{b["cases"]})' for b in r.get("ranking", []))
        rows.append([name, f'{rec.get("backend")} / {rec.get("method")}', order])
    rankings = table(["machine", "choice", "ranking (Mrays/s, cases conforming)"], rows)
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
    speedups = table(["machine", "backend", "device there", "device here", "cases", "geometric mean", "least",
                      "greatest"], rows) if rows else ""
    return PAGE.page("flatmarch: machines compared", PAGE.machines(
        html_(machine_table), html_(speed), html_(rankings), names[0], html_(speedups)))


def read_results(path):
    """A results file of `flatmarch report`; exits with a message for anything else."""
    try:
        with open(path) as f:
            r = json.load(f)
    except (OSError, ValueError) as e:
        sys.exit(f"error: {path}: {e}")
    missing = [k for k in ("fingerprint", "matrix", "ranking") if not isinstance(r, dict) or k not in r]
    if missing:
        sys.exit(f'error: {path}: no "{missing[0]}": not a results file of `flatmarch report`')
    return r


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("results", nargs="+", help="results.json files of flatmarch report")
    parser.add_argument("-o", "--out", required=True, help="output folder")
    parser.add_argument("--previous", help="an earlier run's results.json: the change per case")
    args = parser.parse_args()
    all_results = [read_results(path) for path in args.results]
    previous = read_results(args.previous) if args.previous else None
    if previous is not None and len(all_results) > 1:
        parser.error("--previous compares one run with an earlier one: give one results file")
    os.makedirs(args.out, exist_ok=True)
    use_registry(all_results)
    use_vocabulary(all_results)
    if len(all_results) == 1:
        images = os.path.join(os.path.dirname(os.path.abspath(args.results[0])), "images")
        page = one_machine(all_results[0], images, previous, args.previous)
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
