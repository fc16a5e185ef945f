// A run's journal: each finished case appended beside the output as it finishes, so that a run
// stopped part way (Ctrl-C, a scheduler's time limit or preemption, a crash of the run itself)
// resumes where it stopped (`--resume`) and ends with what an uninterrupted run gives.
//
// The file is JSON lines: a header {"format": "flatmarch-journal/1", "command", "fingerprint",
// "options", "cases": [keys]}, then one {"key", "record"} a finished case, each line written whole
// by one write(2) and synced (fdatasync) before the next case starts, then {"complete": true} once
// the run has written its results. A last line cut short (the process killed while writing it)
// is dropped; any other bad line is refused.
#pragma once

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

namespace flatmarch::reports {

inline constexpr const char* kJournalFormat = "flatmarch-journal/1";

// A journal's header for `command`: its fingerprint, options and case keys.
nlohmann::json journal_header(const std::string& command, const nlohmann::json& fingerprint,
                              const nlohmann::json& options, const std::vector<std::string>& cases);

class Journal {
 public:
  // Starts the journal of a new run at `path`. Refuses (std::invalid_argument) where a journal
  // of a run that did not complete is there: that run is to be resumed or its journal removed.
  static Journal start(const std::filesystem::path& path, const nlohmann::json& header);
  // Reopens the journal at `path` to resume its run, which must be the one `header` describes
  // (the same build, machine but its host name, options and cases): the finished cases' records
  // by key into `finished` (all of them where the run completed). Where there is no journal (the
  // run was stopped before it made one), starts one. Refuses (std::invalid_argument, naming the
  // file and why) a foreign or damaged journal, or one of another run.
  static Journal resume(const std::filesystem::path& path, const nlohmann::json& header,
                        std::map<std::string, nlohmann::json>& finished);

  Journal(Journal&& other) noexcept;
  Journal& operator=(Journal&&) = delete;
  Journal(const Journal&) = delete;
  ~Journal();

  // Appends a finished case, synced.
  void append(const std::string& key, const nlohmann::json& record);
  // Marks the run complete (its results written).
  void complete();
  const std::filesystem::path& path() const { return path_; }

 private:
  Journal(std::filesystem::path path, int fd) : path_(std::move(path)), fd_(fd) {}
  void write_line(const nlohmann::json& line);

  std::filesystem::path path_;
  int fd_ = -1;
};

}  // namespace flatmarch::reports
