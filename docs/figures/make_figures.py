#!/usr/bin/env python3
"""The figures of docs/: one Markdown page per benchmark JSON file in bench/results/.

Each bench/results/NAME.json is what a Google Benchmark program writes with --benchmark_out=FILE
--benchmark_out_format=json; it becomes NAME.md beside this script. A page begins with the
machine and the date the JSON records (the CPU model, instruction set and devices are there when
the program added flatmarch's fingerprint to its context: a run with --shard=I/N does), then a
table of the medians per case (Google Benchmark's "median" aggregates when the run had
repetitions, else its single runs), a section per case family. simd_bench's page adds the SIMD
backend's speed-ups over the scalar backend per instruction set, scene and method, and that
speed-up over the instruction set's lanes (the lane efficiency), by bench/speedups.py's rules.

The programs the docs cite each have a page even before their JSON is there: it says which
command makes the JSON. README.md here lists every page. The pages are made, not written: edit
this script or the data, then run it again.

Usage: python3 docs/figures/make_figures.py [--data DIR] [--out DIR]
"""
import argparse
import json
import math
import os
import re
import sys
import textwrap

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "bench"))
sys.dont_write_bytecode = True  # nothing written into bench/
import speedups  # noqa: E402  (bench/speedups.py: the speed-up and lane-efficiency rules)

MARK = "<!-- made by docs/figures/make_figures.py from "

# The programs the docs link a page of, what each measures and a command that makes its JSON
# (run from the repository root; the benchmark programs are built with the tests, in build/).
KNOWN = {
    "simd_bench": (
        "the SIMD backend per scene, method and instruction set, beside the scalar backend",
        ["build/bench/simd_bench --shard=1/1",
         "--benchmark_repetitions=3 --benchmark_report_aggregates_only=true",
         "--benchmark_out=bench/results/simd_bench.json --benchmark_out_format=json"]),
    "kernel_bench": (
        "every kernel backend and method on the gallery at 320x180: rays a second and steps",
        ["build/bench/kernel_bench --shard=1/1",
         "--benchmark_repetitions=3 --benchmark_report_aggregates_only=true",
         "--benchmark_out=bench/results/kernel_bench.json --benchmark_out_format=json"]),
    "gpu_bench": (
        "the OpenGL and Vulkan backends side by side, a frame's fixed cost and time on the device",
        ["build/bench/gpu_bench --shard=1/1 --benchmark_filter='^(opengl|vulkan|fixed)/.*/640x360'",
         "--benchmark_repetitions=3 --benchmark_report_aggregates_only=true",
         "--benchmark_out=bench/results/gpu_bench.json --benchmark_out_format=json"]),
    "web_bench": (
        "the exported page in headless Chromium, beside the original app's shaders",
        ["build/bench/web_bench --shard=1/1 --peer-shaders=DIR --size=320x180",
         "--benchmark_repetitions=3 --benchmark_report_aggregates_only=true",
         "--benchmark_out=bench/results/web_bench.json --benchmark_out_format=json"]),
    "startup_bench": (
        "how long each command takes to start and do a small piece of work",
        ["build/bench/startup_bench --shard=1/1",
         "--benchmark_repetitions=20 --benchmark_report_aggregates_only=true",
         "--benchmark_out=bench/results/startup_bench.json --benchmark_out_format=json"]),
    "vector_width_bench": (
        "float additions in vectors of each width on one core: whether 512-bit operations run at "
        "full width",
        ["build/bench/vector_width_bench",
         "--benchmark_repetitions=3 --benchmark_report_aggregates_only=true",
         "--benchmark_out=bench/results/vector_width_bench.json --benchmark_out_format=json"]),
}

# Keys of a benchmark entry that are not user counters.
STANDARD = {
    "name", "family_index", "per_family_instance_index", "run_name", "run_type", "repetitions",
    "repetition_index", "threads", "iterations", "real_time", "cpu_time", "time_unit",
    "aggregate_name", "aggregate_unit", "label", "error_occurred", "error_message",
}
TO_MS = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}
# What the acceptance check of docs/ refuses: a run of 7 to 40 hexadecimal digits (a commit).
HEXLIKE = re.compile(r"\b[0-9a-f]{7,40}\b")


def number(v):
    """Three significant digits, large values with k, M or G, never a long run of digits."""
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "-"
    if not isinstance(v, (int, float)):
        return str(v)
    a = float(f"{abs(v):.3g}")  # as it will print: 999 999 is 1.00 M, not 1000 k
    # From 10 000 on in thousands (10.0 k, 934 k), so that no figure has five digits.
    for at, scale, suffix in ((1e9, 1e9, " G"), (1e6, 1e6, " M"), (1e4, 1e3, " k")):
        if a >= at:
            return number(v / scale) + suffix
    if a == 0:
        return "0"
    if a < 1e-3:  # 6.08e-05: written out, its run of zeros reads as a hash to a grep
        return f"{v:.3g}"
    if float(v).is_integer() and a < 1e4:
        return str(int(v))
    decimals = max(0, 2 - int(math.floor(math.log10(a))))
    return f"{v:.{decimals}f}"


def case_name(b):
    return re.sub(r"/real_time$", "", b.get("run_name", b["name"]))


def machine_lines(context, runs):
    """The machine and the date, from the JSON's context: the page's lines, and the index's."""
    fp = {k[len("fingerprint/"):]: v for k, v in context.items() if k.startswith("fingerprint/")}
    cpu = fp.get("cpu/model")
    isa = fp.get("cpu/isa")
    lanes = fp.get("cpu/simd_lanes")
    isas_run = list(dict.fromkeys(m[1] for m in (re.fullmatch(r"simd/\w+/\w+/(\w+)/threads:\d+",
                                                                case_name(b)) for b in runs) if m))
    parts = [cpu or "CPU model not recorded (the program ran without --shard, which adds "
             "flatmarch's fingerprint to the JSON)"]
    if isa:
        parts.append(f"SIMD instruction set {isa}" + (f", {lanes} lanes" if lanes else ""))
    # The fingerprint's lists come flattened: cpu/isas/0, cpu/isas/1, ...
    isas = [fp[k] for k in sorted((k for k in fp if re.fullmatch(r"cpu/isas/\d+", k)),
                                  key=lambda k: int(k.rsplit("/", 1)[1]))]
    if isas:
        parts.append("runs " + ", ".join(isas))
    elif isas_run:
        parts.append("timed on " + ", ".join(isas_run))
    cpus = context.get("num_cpus")
    mhz = context.get("mhz_per_cpu")
    if cpus:
        parts.append(f"{cpus} CPUs" + (f" at {mhz} MHz" if mhz else ""))
    def size(n):
        mib = 1 << 20
        return f"{n // mib} MiB" if n >= mib and n % mib == 0 else f"{n // 1024} KiB"
    caches = [f"L{c['level']} {c['type'].lower()} {size(c['size'])}"
              for c in context.get("caches", []) if "size" in c and "level" in c and "type" in c]
    lines = ["- Machine: " + "; ".join(parts) + "."]
    if caches:
        lines.append("- Caches: " + ", ".join(caches) + ".")
    devices = []
    if fp.get("opengl/renderer"):
        devices.append("OpenGL " + fp["opengl/renderer"] +
                       (" (software)" if fp.get("opengl/software") == "true" else ""))
    if fp.get("vulkan/device"):
        devices.append("Vulkan " + fp["vulkan/device"] +
                       (" (software)" if fp.get("vulkan/software") == "true" else ""))
    if devices:
        lines.append("- Devices: " + "; ".join(devices) + ".")
    build = [v for v in (fp.get("build/type"), fp.get("build/compiler")) if v]
    if build:
        lines.append("- Build: " + ", ".join(build) + "; OS " + fp.get("os", "?") + ".")
    date = context.get("date", "date not recorded")
    lines.append("- Measured: " + date + ".")
    if context.get("flatmarch_flags"):
        lines.append(f"- Flags: `{context['flatmarch_flags']}`.")
    lines = [textwrap.fill(line, width=100, subsequent_indent="  ", break_long_words=False,
                           break_on_hyphens=False) for line in lines]
    return lines, f"{cpu or 'CPU not recorded'}, {cpus or '?'} CPUs; {date}"


def medians_section(runs, medians):
    """A table per case family (the name's first part): time a frame and every counter."""
    what = "Medians of the repetitions" if medians else "Single runs (no repetitions)"
    out = [f"## {what}", ""]
    families = {}
    for b in runs:
        name = case_name(b)
        family, _, rest = name.partition("/")
        families.setdefault(family, []).append((rest or name, b))
    for family, cases in families.items():
        counters = list(dict.fromkeys(k for _, b in cases for k, v in b.items()
                                      if k not in STANDARD and isinstance(v, (int, float))))
        labels = list(dict.fromkeys(b.get("label", "") for _, b in cases))
        per_case_label = len(labels) > 1
        out.append(f"### {family}")
        out.append("")
        if labels and labels[0] and not per_case_label:
            out += [f"Label: {labels[0]}", ""]
        head = ["case", "ms"] + counters + (["label"] if per_case_label else [])
        out.append("| " + " | ".join(head) + " |")
        out.append("|---|" + "---:|" * (1 + len(counters)) + ("---|" if per_case_label else ""))
        for rest, b in cases:
            if b.get("error_occurred"):
                cells = [f"error: {b.get('error_message', '?')}"] + [""] * len(counters)
            else:
                ms = b["real_time"] * TO_MS.get(b.get("time_unit", "ns"), 1e-6)
                cells = [number(ms)] + [number(b.get(k)) for k in counters]
            if per_case_label:
                cells.append(b.get("label", ""))
            out.append(f"| {rest} | " + " | ".join(cells) + " |")
        out.append("")
    return out


def speedups_section(runs_by_name):
    """simd_bench: speedups.py's rows as one table."""
    rows = speedups.table(runs_by_name)
    if not rows:
        return ["## Speed-ups over the scalar backend", "",
                "This run has no scalar/METHOD/SCENE case with a SIMD case beside it.", ""]
    out = ["## Speed-ups over the scalar backend", "",
           prose("Per scene, method and instruction set, as `bench/speedups.py` computes them: *one "
           "thread* is the SIMD backend's rays a second on one thread over the scalar backend's; "
           "*per lane* is that over the instruction set's lanes (the lane efficiency: 1 would be "
           "every lane running the scalar backend's ray as fast); *busy* is the share of lanes "
           "busy; *all cores* is the SIMD backend on every core over the scalar backend on one; "
           "*scaling* is all cores over one thread."), "",
           "| scene | method | isa | lanes | one thread | per lane | busy | all cores | scaling |",
           "|---|---|---|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        def x(key):
            v = r.get(key)
            return "-" if v is None else number(v) + "x"
        out.append(f"| {r['scene']} | {r['method']} | {r['isa']} | {r.get('lanes') or '-'} | "
                   f"{x('speedup_one_thread')} | {number(r.get('lane_efficiency'))} | "
                   f"{number(r.get('lanes_busy'))} | {x('speedup_all_cores')} | {x('scaling')} |")
    out.append("")
    return out


def page(name, path):
    """The page of one JSON file, and its one-line summary for the index."""
    runs_by_name, context = speedups.figures(path)
    with open(path) as f:
        medians = any(b.get("aggregate_name") == "median" for b in json.load(f)["benchmarks"])
    runs = list(runs_by_name.values())
    what = KNOWN.get(name, ("",))[0]
    lines = [f"{MARK}bench/results/{name}.json; run it again rather than edit this -->",
             f"# {name}" + (f": {what}" if what else ""), ""]
    machine, summary = machine_lines(context, runs)
    lines += machine + [""]
    if not runs:
        lines += ["The file holds no benchmark runs.", ""]
    else:
        lines += medians_section(runs, medians)
        if name.startswith("simd_bench"):
            lines += speedups_section(runs_by_name)
    return "\n".join(lines), summary


def prose(text):
    return textwrap.fill(text, width=100, break_long_words=False, break_on_hyphens=False)


def waiting_page(name):
    what, command = KNOWN[name]
    return "\n".join([
        f"{MARK}bench/results/{name}.json, which is not there yet; run it again rather than edit this -->",
        f"# {name}: {what}", "",
        prose(f"No measurement yet: `bench/results/{name}.json` is not there. Make it on the "
              "machine to be measured (a Release build gives the figures a user sees), then run "
              "`python3 docs/figures/make_figures.py`:"), "",
        "```sh", " \\\n  ".join(command), "```", ""])


def main():
    parser = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        epilog="With no JSON in the data folder every known program's page says how to make its "
               "JSON, and the script says so.")
    parser.add_argument("--data", default=os.path.join(HERE, "..", "..", "bench", "results"),
                        help="folder of benchmark JSON files (default: bench/results/)")
    parser.add_argument("--out", default=HERE,
                        help="folder for the pages (default: this script's folder)")
    args = parser.parse_args()

    inputs = sorted(f[:-5] for f in os.listdir(args.data) if f.endswith(".json")) \
        if os.path.isdir(args.data) else []
    written, index = {}, []
    for name in inputs:
        try:
            text, summary = page(name, os.path.join(args.data, name + ".json"))
        except (OSError, ValueError, KeyError, TypeError) as e:
            print(f"make_figures.py: {args.data}/{name}.json: not benchmark JSON ({e})",
                  file=sys.stderr)
            return 2
        written[name] = text
        index.append(f"- [{name}]({name}.md): {summary}")
    for name in KNOWN:
        if name not in written:
            written[name] = waiting_page(name)
            index.append(f"- [{name}]({name}.md): no measurement yet")
    if not inputs:
        print(f"make_figures.py: {args.data} holds no *.json: every page says which command "
              "makes its JSON; put the JSON there and run this again")
    lines = [f"{MARK}bench/results/; run it again rather than edit this -->",
             "# Figures", "",
             prose("Measured figures for the pages of docs/, each page made from one benchmark JSON file "
             "in `bench/results/` by `python3 docs/figures/make_figures.py`, which prints the machine and "
             "the date it was measured. A figure belongs to its machine: run the command on "
             "yours to see your own."), ""]
    lines += ["No JSON in `bench/results/` yet." if not inputs else f"{len(inputs)} files in `bench/results/`.", ""]
    lines += sorted(index) + [""]
    written["README"] = "\n".join(lines)

    os.makedirs(args.out, exist_ok=True)
    for name in os.listdir(args.out):  # pages of data since removed
        path = os.path.join(args.out, name)
        if name.endswith(".md") and name[:-3] not in written:
            with open(path) as f:
                if f.readline().startswith(MARK):
                    os.remove(path)
                    print(f"make_figures.py: removed {path} (its data is gone)")
    for name, text in written.items():
        path = os.path.join(args.out, name + ".md")
        for k, line in enumerate(text.splitlines(), 1):
            if HEXLIKE.search(line):
                print(f"make_figures.py: {path}:{k}: looks like a commit hash (docs/ must hold "
                      f"none): {line.strip()}", file=sys.stderr)
        with open(path, "w") as f:
            f.write(text)
        print(f"make_figures.py: wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
