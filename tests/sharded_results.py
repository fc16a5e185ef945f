"""What the tests of sharded runs (slurm_test.py, workflow_test.py) compare: the fields of a
report's results that every run measures alike."""


def deterministic_report(doc):
    """The matrix's verdicts and step counts, the sweep's points, re-checks and recommended
    points, the recommended parameters: all but the timings and what is ranked by them."""
    cases = [{k: v for k, v in c.items() if k not in ("time_ms", "time_samples_ms", "counters")}
             | {"steps": c["counters"]["steps_mean"], "crossings": c["counters"]["crossings_mean"]}
             for c in doc["matrix"]["cases"]]
    points = [{k: v for k, v in p.items() if k != "time_ms"} for p in doc["sweep"]["points"]]
    picks = [(g["surface_type"], g["method"], g["precision"],
              g["recommended"] and (g["recommended"]["eps"], g["recommended"]["offset"]))
             for g in doc["sweep"]["analysis"]]
    return (cases, points, doc["sweep"]["confirmations"], picks,
            doc["recommendation"].get("parameters"))
