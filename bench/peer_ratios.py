#!/usr/bin/env python3
"""Our GPU backends against the original web app, from one gpu_bench run (see bench/gpu_bench.cpp).

Reads the JSON of a run with the app's shaders (--peer-shaders=DIR, filter peer/): for each of the
app's views, the app's milliseconds a frame and, per backend and method, ours and the speed-up
(the app's time over ours, both from this run); then per backend and method the geometric mean
and the smallest speed-up over the views. Medians when the run has repetitions. Prints Markdown.

Usage: python3 bench/peer_ratios.py gpu.json
"""
import argparse
import json
import math
import re
import sys
from collections import defaultdict

from side_by_side import figures, milliseconds


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("json")
    args = parser.parse_args()
    app = {}
    ours = defaultdict(dict)  # (backend, method) -> {view: ms}
    views = []
    for name, run in figures(args.json).items():
        if "error_message" in run:
            continue
        m = re.match(r"^peer/app/(\w+)(?:/real_time)?$", name)
        if m:
            app[m.group(1)] = milliseconds(run)
            continue
        m = re.match(r"^peer/(\w+)/(\w+)/(\w+)(?:/real_time)?$", name)
        if m:
            backend, view, method = m.groups()
            ours[(backend, method)][view] = milliseconds(run)
            if view not in views:
                views.append(view)
    if not app:
        sys.exit("peer_ratios: the run has no peer/app cases (run gpu_bench with --peer-shaders=DIR)")
    columns = sorted(ours)
    print("| view | app ms | " + " | ".join(f"{b} {m} ms (x)" for b, m in columns) + " |")
    print("|---|---:|" + "---:|" * len(columns))
    for view in views:
        if view not in app:
            continue
        cells = []
        for key in columns:
            ms = ours[key].get(view)
            cells.append("" if ms is None else f"{ms:.1f} ({app[view] / ms:.1f}x)")
        print(f"| {view} | {app[view]:.0f} | " + " | ".join(cells) + " |")
    print()
    print("| backend | method | geometric mean | smallest | views |")
    print("|---|---|---:|---:|---:|")
    for backend, method in columns:
        ratios = {v: app[v] / ms for v, ms in ours[(backend, method)].items() if v in app}
        if not ratios:
            continue
        mean = math.exp(sum(math.log(r) for r in ratios.values()) / len(ratios))
        low = min(ratios, key=ratios.get)
        print(f"| {backend} | {method} | {mean:.1f}x | {ratios[low]:.1f}x ({low}) | {len(ratios)} |")


if __name__ == "__main__":
    main()
