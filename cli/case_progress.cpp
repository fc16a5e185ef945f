#include "cli/case_progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include <nlohmann/json.hpp>

namespace flatmarch::cli {

namespace {

double seconds_now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

constexpr int kBarWidth = 24;
// A log gets a line this often while a stage runs; a terminal's line is redrawn this often.
constexpr double kLogEvery = 5.0, kTerminalEvery = 0.5;

}  // namespace

std::string duration_words(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  if (s < 60) return std::to_string(s) + " s";
  if (s < 3600) return std::to_string(s / 60) + " min " + std::to_string(s % 60) + " s";
  return std::to_string(s / 3600) + " h " + std::to_string(s % 3600 / 60) + " min";
}

CaseProgress::CaseProgress(std::string command,
                           const std::vector<std::pair<std::string, double>>& cases, bool quiet,
                           const std::string& log_file)
    : command_(std::move(command)),
      quiet_(quiet),
      tty_(isatty(fileno(stderr)) != 0),
      start_(seconds_now()),
      last_finish_(start_) {
  std::map<std::string, std::vector<std::pair<std::string, double>>> by_stage;
  std::vector<std::string> order;
  for (const auto& c : cases) {
    const std::string stage = reports::case_groups(c.first).stage;
    if (!by_stage.count(stage)) order.push_back(stage);
    by_stage[stage].push_back(c);
  }
  for (const std::string& name : order) {
    for (const auto& c : by_stage[name]) stage_of_[c.first] = stages_.size();
    stages_.push_back({name, reports::StageEstimate(by_stage[name])});
  }
  if (!log_file.empty()) {
    log_ = std::fopen(log_file.c_str(), "w");
    if (!log_) throw std::runtime_error("--progress-log: cannot write " + log_file);
  }
  advance(start_);
  if (!quiet_ && !stages_.empty()) ticker_ = std::thread([this] { tick(); });
}

CaseProgress::~CaseProgress() {
  close();
}

void CaseProgress::resumed(const std::string& key) {
  const std::lock_guard<std::mutex> lock(mutex_);
  const auto it = stage_of_.find(key);
  if (it == stage_of_.end() || !resumed_.insert(key).second) return;
  Stage& s = stages_[it->second];
  s.estimate.drop(key);
  ++s.resumed;
  last_finish_ = seconds_now();
  advance(last_finish_);
}

void CaseProgress::advance(double now) {
  while (current_ < stages_.size() &&
         stages_[current_].estimate.done() == stages_[current_].estimate.total())
    ++current_;
  if (current_ < stages_.size() && stages_[current_].started < 0.0) stages_[current_].started = now;
}

void CaseProgress::finished(const std::string& key) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (resumed_.count(key)) return;  // shown, but not run now
  const double now = seconds_now();
  const double seconds = now - last_finish_;  // cases run one at a time
  last_finish_ = now;
  const auto it = stage_of_.find(key);
  if (it == stage_of_.end()) return;
  if (it->second != current_) {  // a new stage: the last one's line is finished
    if (drawn_) draw(true);
    current_ = it->second;
    drawn_ = false;
  }
  Stage& s = stages_[current_];
  if (s.started < 0.0) s.started = now - seconds;
  s.estimate.finished(key, seconds);
  if (log_) {
    const nlohmann::json line = {{"stage", s.name},
                                 {"key", key},
                                 {"t", now - start_},
                                 {"seconds", seconds},
                                 {"cost", s.estimate.cost_of(key)},
                                 {"left", s.estimate.seconds_left()},
                                 {"done", s.estimate.done()},
                                 {"total", s.estimate.total()}};
    std::fprintf(log_, "%s\n", line.dump().c_str());
    std::fflush(log_);
  }
  if (s.estimate.done() == s.estimate.total()) {
    if (drawn_ || now - s.started >= 1.0) draw(true);
    drawn_ = false;
    advance(now);
    return;
  }
  if (tty_ || now - last_line_ >= kLogEvery) draw(false);
}

void CaseProgress::say(const std::string& lines) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (tty_ && drawn_) std::fputs("\r\033[K", stderr);
  std::fputs(lines.c_str(), stderr);
  if (tty_ && drawn_) draw(false);
}

void CaseProgress::draw(bool final) {
  if (quiet_ || current_ >= stages_.size()) return;
  const Stage& s = stages_[current_];
  const double now = seconds_now();
  const double spent = s.started < 0.0 ? 0.0 : now - s.started;
  // While a case runs, the estimate made when the last one ended, less the time since.
  const double left = std::max(0.0, s.estimate.seconds_left() - (now - last_finish_));
  const double fraction = final ? 1.0 : s.estimate.fraction_done();
  const int done = s.estimate.done() + s.resumed, total = s.estimate.total() + s.resumed;
  std::string line = command_ + ": " + s.name;
  if (tty_) {
    line.resize(std::max<size_t>(line.size(), command_.size() + 10), ' ');
    const int filled = static_cast<int>(std::lround(fraction * kBarWidth));
    line += " [" + std::string(static_cast<size_t>(filled), '#') +
            std::string(static_cast<size_t>(kBarWidth - filled), '.') + "]";
  }
  char figures[96];
  std::snprintf(figures, sizeof figures, " %3.0f%%  %d/%d cases", 100.0 * fraction, done, total);
  line += figures;
  line += final ? ", " + duration_words(spent) : ", about " + duration_words(left) + " left";
  if (tty_)
    std::fprintf(stderr, "\r\033[K%s%s", line.c_str(), final ? "\n" : "");
  else
    std::fprintf(stderr, "%s\n", line.c_str());
  std::fflush(stderr);
  drawn_ = !final;
  last_line_ = now;
}

void CaseProgress::tick() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!closed_) {
    wake_.wait_for(lock, std::chrono::duration<double>(tty_ ? kTerminalEvery : 1.0));
    if (closed_) break;
    const double now = seconds_now();
    // Short work stays silent: a stage is shown once it has run a second.
    if (current_ >= stages_.size() || stages_[current_].started < 0.0 ||
        now - stages_[current_].started < 1.0)
      continue;
    if (stages_[current_].estimate.done() == stages_[current_].estimate.total()) continue;
    if (tty_ || now - last_line_ >= kLogEvery) draw(false);
  }
}

void CaseProgress::close() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (closed_) return;
    closed_ = true;
    // A stage cut short (the run stopped): its line as it stood.
    if (drawn_ && tty_) std::fputs("\n", stderr);
    drawn_ = false;
  }
  wake_.notify_all();
  if (ticker_.joinable()) ticker_.join();
  if (log_) std::fclose(log_);
  log_ = nullptr;
}

}  // namespace flatmarch::cli
