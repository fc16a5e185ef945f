#include "history/database.hpp"

#include <sqlite3.h>

#include <ctime>
#include <stdexcept>

namespace flatmarch::history {

namespace fs = std::filesystem;

const char* const kSchemaV1 = R"(
CREATE TABLE runs(
  id INTEGER PRIMARY KEY,
  digest TEXT NOT NULL UNIQUE,
  kind TEXT NOT NULL,
  commit_id TEXT NOT NULL,
  created TEXT NOT NULL,
  added TEXT NOT NULL,
  machine TEXT NOT NULL,
  machine_text TEXT NOT NULL,
  build TEXT NOT NULL,
  options TEXT NOT NULL,
  source TEXT NOT NULL,
  page TEXT NOT NULL DEFAULT '');
CREATE TABLE measurements(
  run INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
  case_name TEXT NOT NULL,
  figure TEXT NOT NULL,
  value REAL,
  text TEXT,
  spread REAL NOT NULL DEFAULT 0,
  repetitions INTEGER NOT NULL DEFAULT 1,
  PRIMARY KEY(run, case_name, figure));
)";

namespace {

// 1 -> 2: how each figure is judged (the timings by name, every other figure deterministic, as
// version 1 kept only those), the baseline that gated each run (unknown for the old ones), and
// an index for reading a series.
const char* const kMigrateV1ToV2 = R"(
ALTER TABLE measurements ADD COLUMN judged TEXT NOT NULL DEFAULT 'deterministic';
UPDATE measurements SET judged = 'higher_is_better' WHERE figure = 'rays_per_s';
UPDATE measurements SET judged = 'lower_is_better' WHERE figure = 'real_time';
ALTER TABLE runs ADD COLUMN baseline TEXT NOT NULL DEFAULT '';
CREATE INDEX measurements_by_case ON measurements(case_name, figure);
)";

// A prepared statement, finalised when it goes.
class Statement {
 public:
  Statement(sqlite3* db, const char* sql) : db_(db) {
    if (sqlite3_prepare_v2(db, sql, -1, &s_, nullptr) != SQLITE_OK)
      throw std::runtime_error(std::string("history: ") + sqlite3_errmsg(db));
  }
  ~Statement() { sqlite3_finalize(s_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  Statement& bind(int at, const std::string& v) {
    sqlite3_bind_text(s_, at, v.c_str(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
    return *this;
  }
  Statement& bind(int at, double v) {
    sqlite3_bind_double(s_, at, v);
    return *this;
  }
  Statement& bind(int at, int64_t v) {
    sqlite3_bind_int64(s_, at, v);
    return *this;
  }
  Statement& bind_null(int at) {
    sqlite3_bind_null(s_, at);
    return *this;
  }
  // The next row: true while there is one.
  bool step() {
    const int rc = sqlite3_step(s_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    throw std::runtime_error(std::string("history: ") + sqlite3_errmsg(db_));
  }
  void reset() {
    sqlite3_reset(s_);
    sqlite3_clear_bindings(s_);
  }
  std::string text(int column) const {
    const unsigned char* t = sqlite3_column_text(s_, column);
    return t ? reinterpret_cast<const char*>(t) : "";
  }
  double number(int column) const { return sqlite3_column_double(s_, column); }
  int64_t integer(int column) const { return sqlite3_column_int64(s_, column); }

 private:
  sqlite3* db_;
  sqlite3_stmt* s_ = nullptr;
};

}  // namespace

Database::Database(const fs::path& path) : path_(path) {
  const bool existed = fs::exists(path);
  if (existed && !fs::is_regular_file(path))
    throw std::runtime_error(path.string() + ": not a file");
  if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr) !=
      SQLITE_OK) {
    const std::string why = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    throw std::runtime_error(path.string() + ": cannot open the history database: " + why);
  }
  sqlite3_busy_timeout(db_, 10000);  // another process adding: wait for it, within a bound
  try {
    exec("PRAGMA foreign_keys = ON");
    int32_t application = 0;
    int tables = 0;
    {
      // The first read of a file that is not SQLite fails here: "file is not a database".
      Statement s(db_, "PRAGMA application_id");
      if (s.step()) application = static_cast<int32_t>(s.integer(0));
      Statement t(db_, "SELECT count(*) FROM sqlite_master");
      if (t.step()) tables = static_cast<int>(t.integer(0));
    }
    if (tables == 0) {
      // A new database: this schema, made as version 1 was and migrated, so that every
      // database has come the same way.
      exec("BEGIN");
      exec(kSchemaV1);
      exec(("PRAGMA application_id = " + std::to_string(kApplicationId)).c_str());
      exec("PRAGMA user_version = 1");
      exec("COMMIT");
    } else if (application != kApplicationId) {
      throw std::runtime_error("an SQLite database of another program (application_id " +
                               std::to_string(application) + "), not flatmarch's history");
    }
    const int version = schema_version();
    if (version > kSchemaVersion)
      throw std::runtime_error("written by a newer flatmarch (schema " + std::to_string(version) +
                               "; this one knows up to " + std::to_string(kSchemaVersion) + ")");
    if (version < kSchemaVersion) migrate(version);
  } catch (const std::runtime_error& e) {
    sqlite3_close(db_);
    db_ = nullptr;
    std::string why = e.what();
    if (why.rfind("history: ", 0) == 0) why = why.substr(9);
    throw std::runtime_error(path.string() + ": " + why);
  }
}

Database::~Database() {
  sqlite3_close(db_);
}

void Database::exec(const char* sql) const {
  char* error = nullptr;
  if (sqlite3_exec(db_, sql, nullptr, nullptr, &error) != SQLITE_OK) {
    const std::string why = error ? error : "unknown error";
    sqlite3_free(error);
    throw std::runtime_error("history: " + why);
  }
}

int Database::schema_version() const {
  Statement s(db_, "PRAGMA user_version");
  return s.step() ? static_cast<int>(s.integer(0)) : 0;
}

void Database::migrate(int from) {
  exec("BEGIN");
  try {
    if (from < 1) throw std::runtime_error("history: no schema version: not flatmarch's history");
    if (from < 2) exec(kMigrateV1ToV2);
    exec(("PRAGMA user_version = " + std::to_string(kSchemaVersion)).c_str());
    exec("COMMIT");
  } catch (...) {
    exec("ROLLBACK");
    throw;
  }
}

std::optional<int64_t> Database::add(const Run& run) {
  {
    Statement known(db_, "SELECT id FROM runs WHERE digest = ?");
    known.bind(1, run.digest);
    if (known.step()) return std::nullopt;
  }
  exec("BEGIN");
  try {
    Statement r(db_,
                "INSERT INTO runs(digest, kind, commit_id, created, added, machine, machine_text, "
                "build, options, source, page, baseline) VALUES (?,?,?,?,?,?,?,?,?,?,?,?)");
    r.bind(1, run.digest).bind(2, run.kind).bind(3, run.commit).bind(4, run.created);
    r.bind(5, utc_text(std::time(nullptr)))
        .bind(6, run.machine)
        .bind(7, run.machine_text)
        .bind(8, run.build);
    r.bind(9, run.options).bind(10, run.source).bind(11, run.page).bind(12, run.baseline);
    r.step();
    const int64_t id = sqlite3_last_insert_rowid(db_);
    Statement m(db_,
                "INSERT OR REPLACE INTO measurements(run, case_name, figure, judged, value, text, "
                "spread, repetitions) VALUES (?,?,?,?,?,?,?,?)");
    for (const Measurement& x : run.measurements) {
      m.bind(1, id)
          .bind(2, x.case_name)
          .bind(3, x.figure)
          .bind(4, std::string(to_string(x.judged)));
      if (x.text.empty())
        m.bind(5, x.value).bind_null(6);
      else
        m.bind_null(5).bind(6, x.text);
      m.bind(7, x.spread).bind(8, static_cast<int64_t>(x.repetitions));
      m.step();
      m.reset();
    }
    exec("COMMIT");
    return id;
  } catch (...) {
    exec("ROLLBACK");
    throw;
  }
}

std::vector<RunInfo> Database::runs() const {
  Statement s(db_,
              "SELECT r.id, kind, commit_id, created, machine, machine_text, source, page, "
              "(SELECT count(*) FROM measurements m WHERE m.run = r.id) "
              "FROM runs r ORDER BY created, id");
  std::vector<RunInfo> out;
  while (s.step())
    out.push_back({s.integer(0), s.text(1), s.text(2), s.text(3), s.text(4), s.text(5), s.text(6),
                   s.text(7), static_cast<int>(s.integer(8))});
  return out;
}

std::vector<SeriesKey> Database::series_keys() const {
  return find_series("", "", "");
}

std::vector<SeriesKey> Database::find_series(const std::string& case_name,
                                             const std::string& figure,
                                             const std::string& machine) const {
  Statement s(db_,
              "SELECT DISTINCT m.case_name, m.figure, r.machine, r.build, r.options, m.judged "
              "FROM measurements m JOIN runs r ON r.id = m.run "
              "WHERE (?1 = '' OR m.case_name = ?1) AND (?2 = '' OR m.figure = ?2) "
              "AND (?3 = '' OR r.machine = ?3) "
              "ORDER BY m.case_name, m.figure, r.machine, r.build, r.options");
  s.bind(1, case_name).bind(2, figure).bind(3, machine);
  std::vector<SeriesKey> out;
  while (s.step())
    out.push_back(
        {s.text(0), s.text(1), s.text(2), s.text(3), s.text(4), judged_from_string(s.text(5))});
  return out;
}

std::vector<Point> Database::series(const SeriesKey& key) const {
  Statement s(db_,
              "SELECT r.id, r.commit_id, r.created, r.page, r.baseline, m.value, m.text, m.spread, "
              "m.repetitions FROM measurements m JOIN runs r ON r.id = m.run "
              "WHERE m.case_name = ? AND m.figure = ? AND r.machine = ? AND r.build = ? "
              "AND r.options = ? ORDER BY r.created, r.id");
  s.bind(1, key.case_name).bind(2, key.figure).bind(3, key.machine).bind(4, key.build);
  s.bind(5, key.options);
  std::vector<Point> out;
  while (s.step())
    out.push_back({s.integer(0), s.text(1), s.text(2), s.text(3), s.text(4), s.number(5), s.text(6),
                   s.number(7), static_cast<int>(s.integer(8))});
  return out;
}

}  // namespace flatmarch::history
