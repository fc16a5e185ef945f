// The results database: every run kept in SQLite (a plain file any `sqlite3` opens), its schema
// versioned (PRAGMA user_version) and migrated forward on open.
//
//   runs(id, digest UNIQUE, kind, commit_id, created, added, machine, machine_text, build,
//        options, source, baseline, page)
//   measurements(run -> runs.id, case_name, figure, judged, value, text, spread, repetitions)
//
// A series is one case's figure over the runs of one machine, build and options, in the order
// they were measured (created, then added).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "history/runs.hpp"

struct sqlite3;

namespace flatmarch::history {

// This build's schema. 1: runs and measurements; 2: each measurement says how it is judged, and
// each run which baseline gated it (so that a deterministic change a baseline commit made on
// purpose is accepted), with an index by case.
inline constexpr int kSchemaVersion = 2;
// Ours among SQLite files (PRAGMA application_id): "fmhs".
inline constexpr int32_t kApplicationId = 0x666d6873;

// The first schema, as the first databases were written: kept to test the migration from it.
extern const char* const kSchemaV1;

struct SeriesKey {
  std::string case_name, figure, machine, build, options;
  Judged judged = Judged::kDeterministic;
};

struct Point {
  int64_t run = 0;
  std::string commit, created, page, baseline;
  double value = 0.0;
  std::string text;
  double spread = 0.0;
  int repetitions = 1;
};

struct RunInfo {
  int64_t id = 0;
  std::string kind, commit, created, machine, machine_text, source, page;
  int measurements = 0;
};

class Database {
 public:
  // Opens the database at `path`, made (with this schema) where there is no file, migrated
  // where it has an older schema. std::runtime_error naming the file and why where it is not
  // SQLite, is another program's database, or has a newer schema than this build knows.
  explicit Database(const std::filesystem::path& path);
  ~Database();
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  int schema_version() const;

  // Adds a run and its measurements in one transaction: its id, or nullopt where a run of the
  // same content is there already (adding twice changes nothing).
  std::optional<int64_t> add(const Run& run);

  std::vector<RunInfo> runs() const;
  // Every series, by case, figure, machine, build and options.
  std::vector<SeriesKey> series_keys() const;
  // One series' points in measuring order.
  std::vector<Point> series(const SeriesKey& key) const;
  // The series of a case's figure on every machine (an empty `machine`: all of them).
  std::vector<SeriesKey> find_series(const std::string& case_name, const std::string& figure,
                                     const std::string& machine = "") const;

 private:
  void exec(const char* sql) const;
  void migrate(int from);

  std::filesystem::path path_;
  sqlite3* db_ = nullptr;
};

}  // namespace flatmarch::history
