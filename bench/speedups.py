#!/usr/bin/env python3
"""The SIMD backend's speed-ups and lane efficiency from one simd_bench JSON file.

For each scene and method that has a scalar case (bench/simd_bench.cpp's compared scenes), and for
each instruction set the run timed:
  1 thread     SIMD rays/s on one thread over the scalar backend's (also one thread)
  per lane     that speed-up over the instruction set's lanes: the lane efficiency, the share of
               what these lanes could do if every lane ran the scalar backend's ray as fast
  busy         lanes busy (active lanes over lanes, summed over every pass of the frame)
  step         the lane efficiency's first factor: the instruction set's cheapest step (the
               central packet's one step, peak_steps_per_s) per lane, over the scalar backend's
               steps a second (its rays/s times its steps a ray): what a step costs in lanes
  of peak      its second factor: the share of that peak the frame keeps (simd_bench's of_peak:
               lanes idle, refills, endings, crossings). per lane = step x of peak, since both
               backends take the same steps.
  all cores    SIMD on all cores over the scalar backend on one
  scaling      all cores over one thread, the same instruction set
Medians when the run has repetitions. The header names the CPU and its cores: a figure belongs to
the machine that made it.

Usage: python3 bench/speedups.py simd.json [--min-efficiency sphere=0.6,relaxed=0.6,analytic=0.5]
                                           [--min-scaling 1.85] [--min-speedup 12] [--json out.json]
Exit status 1 if a figure falls below a given minimum (each named in a line of its own).
"""
import argparse
import json
import re
import sys


def figures(path):
    """{name: counters} from the medians when present, else from the single runs."""
    with open(path) as f:
        data = json.load(f)
    runs = data["benchmarks"]
    medians = [b for b in runs if b.get("aggregate_name") == "median"]
    chosen = medians if medians else [b for b in runs if b.get("run_type", "iteration") == "iteration"]
    return {b["run_name"] if "run_name" in b else b["name"]: b for b in chosen}, data.get("context", {})


def cpu_model():
    """This machine's CPU model, from /proc/cpuinfo, or '?' (the JSON does not record it)."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "?"


def thresholds(text):
    """'sphere=0.6,analytic=0.5' -> {'sphere': 0.6, 'analytic': 0.5}."""
    out = {}
    for part in filter(None, (text or "").split(",")):
        method, _, value = part.partition("=")
        out[method.strip()] = float(value)
    return out


def table(runs):
    """Rows of the compared cases: one per scene, method and instruction set."""
    simd = {}
    for name, b in runs.items():
        m = re.fullmatch(r"simd/(\w+)/(\w+)/(\w+)/threads:(\d+)(?:/real_time)?", name)
        if m:
            simd.setdefault((m[1], m[2]), {})[(m[3], int(m[4]))] = b
    rows = []
    for name, b in sorted(runs.items()):
        m = re.fullmatch(r"scalar/(\w+)/(\w+)(?:/real_time)?", name)
        if not m:
            continue
        method, scene = m[1], m[2]
        cases = simd.get((method, scene), {})
        if not cases:
            continue
        scalar = b["rays_per_s"]
        most = max(threads for _, threads in cases)
        for isa in dict.fromkeys(isa for isa, _ in cases):  # in the run's order: best first
            one, top = cases.get((isa, 1)), cases.get((isa, most)) if most > 1 else None
            row = {"scene": scene, "method": method, "isa": isa, "scalar_rays_per_s": scalar}
            if one:
                lanes = one.get("lanes", 0)
                row.update(one_thread_rays_per_s=one["rays_per_s"], speedup_one_thread=one["rays_per_s"] / scalar,
                           lanes=lanes, lanes_busy=one.get("lane_utilisation"))
                if lanes:
                    row["lane_efficiency"] = row["speedup_one_thread"] / lanes
                scalar_steps = scalar * b.get("steps_mean", 0)
                if lanes and scalar_steps > 0 and one.get("peak_steps_per_s"):
                    row["step_per_lane"] = one["peak_steps_per_s"] / lanes / scalar_steps
                if one.get("of_peak") is not None:
                    row["of_peak"] = one["of_peak"]
            if top:
                row.update(threads=most, all_cores_rays_per_s=top["rays_per_s"],
                           speedup_all_cores=top["rays_per_s"] / scalar)
                if one:
                    row["scaling"] = top["rays_per_s"] / one["rays_per_s"]
            rows.append(row)
    return rows


def markdown(rows, context):
    """A table of one-thread speed-ups (lane efficiency in brackets): a row per scene and method,
    a column per instruction set, then two threads over one in the best."""
    isas = list(dict.fromkeys(r["isa"] for r in rows))
    lines = [f"| scene | method | " + " | ".join(isas) + " | all cores / one thread |",
             "|---|---|" + "---|" * len(isas) + "---|"]
    by_case = {}
    for r in rows:
        by_case.setdefault((r["scene"], r["method"]), {})[r["isa"]] = r
    for (scene, method), cells in by_case.items():
        text = []
        for isa in isas:
            r = cells.get(isa, {})
            text.append(f"{r['speedup_one_thread']:.2f}x ({r['lane_efficiency']:.2f})"
                        if r.get("lane_efficiency") is not None else "-")
        scaling = " / ".join(f"{cells[i]['scaling']:.2f}x" for i in isas
                             if i in cells and cells[i].get("scaling") is not None) or "-"
        lines.append(f"| {scene} | {method} | " + " | ".join(text) + f" | {scaling} |")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("input", metavar="simd.json")
    parser.add_argument("--min-efficiency", type=thresholds, default={},
                        help="per method, the least lane efficiency: sphere=0.6,relaxed=0.6,analytic=0.5")
    parser.add_argument("--min-scaling", type=float, default=0.0, help="all cores over one thread")
    parser.add_argument("--min-speedup", type=float, default=0.0, help="all cores over scalar, best ISA")
    parser.add_argument("--json", dest="out", help="also write the rows here")
    parser.add_argument("--markdown", action="store_true",
                        help="print the lane efficiency as a Markdown table instead (scenes by "
                        "method and instruction set: one-thread speed-up, per lane in brackets)")
    args = parser.parse_args()
    runs, context = figures(args.input)
    rows = table(runs)
    if not rows:
        print("speedups.py: no scalar/METHOD/SCENE case with a simd case beside it in " + args.input,
              file=sys.stderr)
        return 2
    if args.markdown:
        print(markdown(rows, context))
        return 0
    print(f"host: {context.get('host_name', '?')}, CPU {cpu_model()}, {context.get('num_cpus', '?')} CPUs, "
          f"{context.get('date', '?')} (the CPU is this machine's: run this where the JSON was made)")
    print(f"{'scene':<16} {'method':<9} {'isa':<7} {'scalar':>8} {'1 thread':>9} {'speedup':>8} "
          f"{'per lane':>8} {'busy':>5} {'step':>5} {'of peak':>7} {'all cores':>10} {'speedup':>8} "
          f"{'scaling':>8}")
    failures = []
    best_isa = {}
    for r in rows:
        best_isa.setdefault((r["scene"], r["method"]), r["isa"])

        def cell(key, fmt, width):
            return f"{r[key]:{width}{fmt}}" if r.get(key) is not None else f"{'-':>{width}}"
        print(f"{r['scene']:<16} {r['method']:<9} {r['isa']:<7} {r['scalar_rays_per_s'] / 1e6:>7.3f}M "
              f"{r.get('one_thread_rays_per_s', 0) / 1e6:>8.2f}M {cell('speedup_one_thread', '.2f', 7)}x "
              f"{cell('lane_efficiency', '.3f', 8)} {cell('lanes_busy', '.2f', 5)} "
              f"{cell('step_per_lane', '.2f', 5)} {cell('of_peak', '.2f', 7)} "
              f"{r.get('all_cores_rays_per_s', 0) / 1e6:>9.2f}M {cell('speedup_all_cores', '.1f', 7)}x "
              f"{cell('scaling', '.2f', 7)}x")
        want = args.min_efficiency.get(r["method"])
        if want is not None and r.get("lane_efficiency") is not None and r["lane_efficiency"] < want:
            failures.append(f"{r['scene']} {r['method']} {r['isa']}: lane efficiency "
                            f"{r['lane_efficiency']:.3f} < {want}")
        if args.min_scaling and r.get("scaling") is not None and r["scaling"] < args.min_scaling:
            failures.append(f"{r['scene']} {r['method']} {r['isa']}: scaling {r['scaling']:.2f} < {args.min_scaling}")
        if (args.min_speedup and best_isa[(r["scene"], r["method"])] == r["isa"]
                and r.get("speedup_all_cores") is not None and r["speedup_all_cores"] < args.min_speedup):
            failures.append(f"{r['scene']} {r['method']} {r['isa']}: all-core speed-up "
                            f"{r['speedup_all_cores']:.1f} < {args.min_speedup}")
    if args.out:
        with open(args.out, "w") as f:
            json.dump({"cpu": cpu_model(), "context": context, "rows": rows}, f, indent=1)
    for line in failures:
        print("below: " + line)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
