// What the report's page shows, worked out from results files: every count, grouping, share and
// change the page's tables hold. make_report.py draws the charts and fills reports/page.html.j2
// with these and the results as they are; it computes none of them. The suite's words (verdicts,
// checks, failure classes and their colours) are conformance/vocabulary.hpp's.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace flatmarch::reports {

// A case's verdict as the page shows it: pass, limit or fail by its accuracy, error, or how a
// supervised run's case ended unfinished; "" for a case not measured against the oracle.
std::string page_verdict(const nlohmann::json& matrix_case);

// The page of one run (`flatmarch report`'s results; `previous`, an earlier run's, or null):
// {"methods", "backends", "surface_types" (the registry's lists, or those of the cases where
// the results predate it), "verdicts" (page_verdict of each matrix case, in order), "summary",
// "ambiguity", "device_time_missing", "gallery", "recommended", "failures", "lanes",
// "unfinished", "shards", "sweep", "prisms", "legend", "previous"}; each a section's table, null
// or empty where the results have nothing for it.
nlohmann::json page_tables(const nlohmann::json& results, const nlohmann::json* previous);

// The page comparing machines, one run each ((path, results), the first the base): {"names"
// (each run's folder and CPU, and GPU where its backends found one), "machine_rows" (the
// fingerprint rows side by side), "speedups" (per later run and backend, the geometric mean,
// least and greatest ratio of the base's frame times over its own on the cases both measured)}.
nlohmann::json machines_tables(const std::vector<std::pair<std::string, nlohmann::json>>& runs);

}  // namespace flatmarch::reports
