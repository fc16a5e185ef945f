// What the history says: every series with its change points, and what a new run changed.
#pragma once

#include <nlohmann/json.hpp>

#include "history/changes.hpp"
#include "history/database.hpp"

namespace flatmarch::history {

// Every series of the database with its points and change points, and the findings:
//   {"runs": [{id, kind, commit, created, machine, machine_text, page}],
//    "series": [{case, figure, judged, machine, build, options, points: [{run, commit, created,
//                value | text, spread, repetitions}], changes: [finding...]}],
//    "findings": [finding...]}
// A finding: {case, figure, judged, machine, kind ("deterministic" or "timing"), at (the point's
// index), run, created, commits: [the last commit before, the first after], before, after (a
// number, or a text), z (timings), worse (for timings and numbers where the direction is known:
// more time, fewer rays a second, more steps, more wrong pixels, a worse verdict), accepted (a
// deterministic change made where the gate's baseline changed too: a baseline commit), open (a
// regression the newest run still shows: a deterministic one not accepted, a timing one the
// series has not come back from within min_change)}. Findings come open
// regressions first, then the rest, each newest first.
nlohmann::json analyse(const Database& db, const ChangeOptions& options = {});

// The findings of `analysed` (analyse's) at each series' newest run: what the last run added
// changed. {"deterministic": [unaccepted deterministic changes], "accepted": [...], "timing":
// [timing changes whose first run after is the newest]}.
nlohmann::json newest_changes(const nlohmann::json& analysed);

}  // namespace flatmarch::history
