#include "reports/journal.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include "reports/shard.hpp"

namespace flatmarch::reports {

using json = nlohmann::json;
namespace fs = std::filesystem;

namespace {

struct Read {
  json header;
  std::vector<json> lines;
  bool complete = false;
  off_t good_bytes = 0;  // the length of its whole lines
};

// Reads a journal; a last line cut short is left out (good_bytes ends before it).
Read read_journal(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument(path.string() + ": cannot read the journal");
  std::stringstream text;
  text << in.rdbuf();
  const std::string all = text.str();
  Read r;
  size_t at = 0;
  int number = 0;
  while (at < all.size()) {
    const size_t nl = all.find('\n', at);
    ++number;
    const bool whole = nl != std::string::npos;
    json line;
    try {
      line = json::parse(all.substr(at, whole ? nl - at : std::string::npos));
    } catch (const json::parse_error&) {
      if (!whole) break;  // cut short: the run was stopped while writing it
      throw std::invalid_argument(path.string() + ": line " + std::to_string(number) +
                                  " is not JSON: a damaged journal");
    }
    if (!whole) break;  // parsed, but its line end never written: dropped too
    if (!line.is_object())
      throw std::invalid_argument(path.string() + ": line " + std::to_string(number) +
                                  " is not a JSON object");
    if (number == 1) {
      if (line.value("format", "") != kJournalFormat)
        throw std::invalid_argument(path.string() + ": not a flatmarch journal (its format is " +
                                    line.value("format", json("none")).dump() + ", not " +
                                    kJournalFormat + ")");
      r.header = std::move(line);
    } else if (line.value("complete", false)) {
      r.complete = true;
    } else {
      if (!line.contains("key") || !line["key"].is_string() || !line.contains("record"))
        throw std::invalid_argument(path.string() + ": line " + std::to_string(number) +
                                    " is not a case's record");
      r.lines.push_back(std::move(line));
    }
    at = nl + 1;
    r.good_bytes = static_cast<off_t>(at);
  }
  if (r.header.is_null())
    throw std::invalid_argument(path.string() + ": an empty journal (no header)");
  return r;
}

std::string system_error(const fs::path& path, const std::string& what) {
  return path.string() + ": " + what + ": " + std::strerror(errno);
}

}  // namespace

json journal_header(const std::string& command, const json& fingerprint, const json& options,
                    const std::vector<std::string>& cases) {
  return {{"format", kJournalFormat},
          {"command", command},
          {"fingerprint", fingerprint},
          {"options", options},
          {"cases", cases}};
}

Journal Journal::start(const fs::path& path, const json& header) {
  if (fs::exists(path)) {
    const Read old = read_journal(path);
    if (!old.complete)
      throw std::invalid_argument(
          path.string() + ": the journal of a run that did not finish (" +
          std::to_string(old.lines.size()) + " of " + std::to_string(old.header["cases"].size()) +
          " cases done): add --resume to finish it, or remove the file to start again");
  }
  const fs::path partial = path.string() + ".new";
  const int fd = ::open(partial.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw std::invalid_argument(system_error(partial, "cannot write the journal"));
  Journal j(partial, fd);
  j.write_line(header);
  if (::rename(partial.c_str(), path.c_str()) != 0)
    throw std::invalid_argument(system_error(path, "cannot write the journal"));
  j.path_ = path;
  return j;
}

Journal Journal::resume(const fs::path& path, const json& header,
                        std::map<std::string, json>& finished) {
  if (!fs::exists(path)) {  // stopped before its first case, or never started: from the start
    finished.clear();
    return start(path, header);
  }
  const Read r = read_journal(path);
  const auto differs = [&](const char* what, const json& a, const json& b) {
    if (a != b)
      throw std::invalid_argument(path.string() + ": the journal of another run (its " + what +
                                  " differ from this one's); remove it to start again");
  };
  differs("command", r.header.value("command", json()), header.value("command", json()));
  differs("build", r.header["fingerprint"].value("build", json()),
          header["fingerprint"].value("build", json()));
  differs("machine", machine_of(r.header), machine_of(header));
  differs("options", r.header.value("options", json()), header.value("options", json()));
  differs("cases", r.header.value("cases", json()), header.value("cases", json()));
  std::set<std::string> keys;
  for (const auto& c : header["cases"]) keys.insert(c.get<std::string>());
  finished.clear();
  for (const json& line : r.lines) {
    const std::string key = line["key"].get<std::string>();
    if (!keys.count(key))
      throw std::invalid_argument(path.string() + ": a record of case " + key +
                                  ", which is not this run's");
    if (!finished.emplace(key, line["record"]).second)
      throw std::invalid_argument(path.string() + ": case " + key + " recorded twice");
  }
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) throw std::invalid_argument(system_error(path, "cannot reopen the journal"));
  // The line cut short, if any, cut off: the next record starts on a line of its own.
  if (::ftruncate(fd, r.good_bytes) != 0 || ::lseek(fd, 0, SEEK_END) < 0) {
    ::close(fd);
    throw std::invalid_argument(system_error(path, "cannot reopen the journal"));
  }
  return Journal(path, fd);
}

Journal::Journal(Journal&& other) noexcept : path_(std::move(other.path_)), fd_(other.fd_) {
  other.fd_ = -1;
}

Journal::~Journal() {
  if (fd_ >= 0) ::close(fd_);
}

void Journal::append(const std::string& key, const json& record) {
  write_line({{"key", key}, {"record", record}});
}

void Journal::complete() {
  write_line({{"complete", true}});
}

void Journal::write_line(const json& line) {
  const std::string text = line.dump(-1, ' ', false, json::error_handler_t::replace) + "\n";
  size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd_, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error(system_error(path_, "cannot write the journal"));
    done += static_cast<size_t>(n);
  }
  if (::fdatasync(fd_) != 0)
    throw std::runtime_error(system_error(path_, "cannot sync the journal"));
}

}  // namespace flatmarch::reports
