// The report: the matrix, the sweep and the scaling series in one results file (with the
// machine's fingerprint), the ranking of backends on this machine with recommended parameters,
// and the regression gate against committed baselines of the deterministic figures.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "reports/matrix.hpp"
#include "reports/scaling.hpp"
#include "reports/shard.hpp"
#include "reports/sweep.hpp"

namespace flatmarch::reports {

struct ReportOptions {
  MatrixOptions matrix;
  SweepOptions sweep;
  ScalingOptions scaling;
  bool sweep_enabled = true, scaling_enabled = true;
  // Scenes of the sweep: every scene when true, else the first scene of each surface type.
  bool sweep_all_scenes = false;
  // Run only this shard of the report's cases (report_cases, split by assign_shards); the
  // results then hold the shard's matrix cases, sweep groups and scaling series and its
  // shard_record, and no ranking, recommendation or gallery: merge_report makes those.
  std::optional<Shard> shard;
};

// The report's cases by key (matrix_case_key, sweep_case_key, scaling_case_key), each with its
// expected seconds on this machine: what a shard holds, and its estimate before it starts.
// The names of the first scene of each surface type (surfaces.hpp), in the scenes' order: the
// sweep's scenes.
std::vector<std::string> first_of_each_surface_type(const std::vector<Scene>& scenes);
// The names of the scene of each surface type with the fewest edges (the first of those), in
// the order of the types' first scenes: those a sampled backend (MatrixOptions::sampled_backends)
// is measured on, the cheapest of each kind of room.
std::vector<std::string> simplest_of_each_surface_type(const std::vector<Scene>& scenes);

// The report's cases, (key, expected seconds), in its order: the matrix's (on `backends`, or on
// backends made here where null: matrix_cases), the sweep's groups, the scaling series.
std::vector<std::pair<std::string, double>> report_cases(const std::vector<Scene>& scenes,
                                                         const ReportOptions& options,
                                                         const MatrixBackends* backends = nullptr);

using ReportProgress =
    std::function<void(const std::string& stage, const std::string& line, int done, int total)>;

// Runs what the options ask on the scenes and returns the results document: "format",
// "created", "fingerprint", "options", "matrix", "sweep", "scaling", "ranking", "recommendation",
// and with matrix images, "gallery" (recommended_gallery()); a shard's: "shard" (shard_record)
// and no ranking, recommendation or gallery. Progress "shard" (a line) says what a shard holds
// and its estimated seconds before it starts.
nlohmann::json run_report(const std::vector<Scene>& scenes, const ReportOptions& options,
                          const ReportProgress& progress);

// The results' header: "format", "created", "fingerprint", "registry" (the lists the page
// draws by), "vocabulary" (the suite's words, conformance/vocabulary.hpp) and "options".
nlohmann::json report_header(const std::vector<Scene>& scenes, const ReportOptions& options);

// The conformance suites of a report's stages: the sweep fixes its suite's mask (one truth for
// every point), so a worker that runs matrix cases after sweep groups keeps one apart.
struct ReportSuites {
  conformance::Suite& matrix;
  conformance::Suite& sweep;
};

// Measures the report's cases that `holds` holds (every case where it is empty): {"matrix"
// (run_matrix's), "sweep" (run_sweep's), "scaling" (run_scaling's), "seconds" per stage}; a stage
// of which it holds no case is left out, unless `every_stage` (a shard's results have each
// enabled stage). The matrix runs on `backends` where given (a worker makes them once). A
// supervised report runs one case a part in its workers and puts them together
// (assemble_report).
nlohmann::json run_report_part(const std::vector<Scene>& scenes, const ReportOptions& options,
                               const std::function<bool(const std::string& key)>& holds,
                               const ReportSuites& suites, const ReportProgress& progress,
                               const MatrixBackends* backends, bool every_stage);

// The case keys a part (or a shard's results) holds results of, in its order: matrix cases,
// sweep groups, scaling series.
std::vector<std::string> report_part_keys(const nlohmann::json& part);

// Puts parts of one run together (run_report_part's, or shards' results, each with its name
// for errors), in the run's order `keys` (report_cases'): {"matrix": the cases, with the
// benchmark runs and the skipped backends; "sweep": the points and re-checks, analysed again
// (merged_sweep); "scaling": the series; "seconds": summed per stage}. `header` is the run's
// (report_header's: options.scenes, registry.methods). Throws std::invalid_argument where two
// parts' sweeps were run with other options.
nlohmann::json assemble_report(
    const nlohmann::json& header,
    const std::vector<std::pair<std::string, const nlohmann::json*>>& parts,
    const std::vector<std::string>& keys);

// A case a supervised report did not finish (`record`: supervise()'s crash, timeout or
// out_of_memory, or {"error"} where the case threw) as the results' "unfinished" list has it:
// {"key", "stage" (matrix, sweep or scaling), "verdict" (crash, timeout, out_of_memory or
// error), "error" (unfinished_summary's words), and the record's seconds, signal_name,
// exit_code, deadline_seconds and stderr_tail}.
nlohmann::json unfinished_entry(const std::string& key, const nlohmann::json& record);
// A matrix case among them as a part for assemble_report: the case at its place in the matrix,
// named as a measured one (name, backend, scene, surface_type, method, width, height) with
// "verdict" and "error" (unfinished_summary's words), so that the ranking counts it as an error
// and the gate as a regression. Null for a sweep group or a scaling series, whose results simply
// lack it.
nlohmann::json unfinished_part(const std::string& key, const nlohmann::json& record,
                               const std::vector<Scene>& scenes, const ReportOptions& options);

// What a whole run makes of its measured results: "ranking", "recommendation" and, with matrix
// images, the oracle's frames and the "gallery"; seconds.gallery.
void finish_report(nlohmann::json& results, const std::vector<Scene>& scenes,
                   const ReportOptions& options);

// Merges the results of a sharded `flatmarch report` (each file's JSON, with its name for
// errors), all of one machine: checks that they are the shards 1..N of one run (as
// merge_conformance) and returns the whole run's results as run_report writes them, the
// matrix's cases, the sweep's points and the scaling series in the run's order, the sweep's
// analysis, the ranking and the recommendation made from them; "merged_from", "hosts"; no
// "gallery" (it renders: the caller's). Throws std::invalid_argument naming the file and why.
nlohmann::json merge_report(const std::vector<std::pair<std::string, nlohmann::json>>& files);

// The backends by the matrix: those whose every case passed the conformance suite first, each
// group by the geometric mean of rays per second over its cases; per backend its pass rate,
// speed, and fastest conforming method.
nlohmann::json rank_backends(const nlohmann::json& matrix);
// A SIMD case's lane efficiency (issue 73): its rays a second on one thread (counter
// one_thread_rays_per_s, or rays_per_s where its frames ran on one) over the scalar backend's
// `scalar_rays_per_s` on the same scene, method and size, over its lanes (counter lanes): the
// share of what these lanes could do if each ran the scalar backend's ray as fast. 0 where a
// figure is missing. rank_backends gives each method's geometric mean (lane_efficiency).
double lane_efficiency(const nlohmann::json& counters, double scalar_rays_per_s);

// The choice for this machine: the top backend and its method, with eps and offset per surface
// type from the sweep (DESIGN.md's defaults where the sweep has no stable point).
nlohmann::json recommend(const nlohmann::json& ranking, const nlohmann::json& sweep);

// `flatmarch select`'s text: the choice, and for `surface_type` (empty: every type) the flags.
std::string describe_selection(const nlohmann::json& results, const std::string& surface_type);

// --- The regression gate.

// The deterministic figures of a results document per case (steps, crossings, conformance
// rates), with the tolerances they are held to, and the timing samples (informative only).
nlohmann::json make_baseline(const nlohmann::json& results);

// Why `baseline` cannot judge `results` (not a baseline file, or measured at another size,
// conform size, eps, offset or max_steps), or "" when it can.
std::string baseline_mismatch(const nlohmann::json& baseline, const nlohmann::json& results);

// Compares results with a baseline: "regressions" (a deterministic figure worse beyond its
// tolerance, or a case that passed now failing), "improvements" (better beyond tolerance: the
// baseline wants updating), "missing" (cases of the baseline not measured now), and
// "timing_warnings" (slower, Mann-Whitney U test over the repetitions at alpha 0.05 and a
// median ratio above 1.1).
nlohmann::json check_baseline(const nlohmann::json& baseline, const nlohmann::json& results);

// check_baseline's findings as the gate prints them, a line each (warnings, improvements,
// regressions) and a summary line; baseline_file names the baseline.
std::string describe_gate(const nlohmann::json& check, const nlohmann::json& baseline,
                          const std::string& baseline_file);

// The two-sided p-value of the Mann-Whitney U test that samples a and b come from one
// distribution (normal approximation with tie correction, as scipy's mannwhitneyu without
// continuity correction); 1 when either has fewer than two samples.
double mann_whitney_p(const std::vector<double>& a, const std::vector<double>& b);

}  // namespace flatmarch::reports
