// What a user waits for before a command does its work: whole `flatmarch` processes, started
// and waited for, per command. A command loads only the libraries it uses (OpenImageIO through
// the image module when it writes an image, EGL or OSMesa when it draws with OpenGL, ...), so
// the cases show each one's price:
//
//   build/bench/startup_bench --benchmark_repetitions=20 --benchmark_report_aggregates_only=true
//
// Names are startup/COMMAND; medians over the repetitions are the figures to quote.
#include <benchmark/benchmark.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "backends/backend.hpp"
#include "bench/gallery.hpp"

extern char** environ;

namespace {

const std::string kSource = FLATMARCH_SOURCE_DIR;
std::string scratch;  // a folder for the files the commands write

// Runs `flatmarch ARGS`, its output discarded; false if it cannot be run or fails.
bool run(const std::vector<std::string>& args) {
  std::vector<std::string> all = {FLATMARCH_BINARY};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) return false;
  int status = 0;
  if (waitpid(pid, &status, 0) != pid) return false;
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

void command(benchmark::State& state, std::vector<std::string> args) {
  if (!run(args)) {  // also warms the page cache
    state.SkipWithError("the command fails");
    return;
  }
  for (auto _ : state)
    if (!run(args)) state.SkipWithError("the command fails");
}

}  // namespace

int main(int argc, char** argv) {
  if (!flatmarch::bench::begin(argc, argv)) return 2;
  scratch = (std::filesystem::temp_directory_path() / "flatmarch_startup_bench").string();
  std::filesystem::create_directories(scratch);
  const std::string torus = kSource + "/scenes/torus.json";
  std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
      {"help", {"--help"}},
      {"inspect", {"inspect", torus}},
      {"trace", {"trace", torus, "--from", "1,1,1", "--dir", "3,1,0"}},
      {"plan", {"plan", torus, "-o", scratch + "/t.svg"}}};
  // A render on the fastest CPU backend the build has, and on its first that compiles a shader
  // of its own (a GPU backend: its driver's start and the compile).
  std::vector<std::string> render = {flatmarch::cpu_backend_names().front()};
  for (const flatmarch::BackendEntry& e : flatmarch::backend_registry())
    if (e.shader) {
      render.push_back(e.name);
      break;
    }
  for (const std::string& b : render)
    cases.push_back(
        {"render_" + b + "_320x180_png",
         {"render", torus, "--backend", b, "--size", "320x180", "-o", scratch + "/" + b + ".png"}});
  cases.push_back({"backends", {"backends"}});
  for (const auto& [name, args] : cases)
    flatmarch::bench::add("startup/" + name, command, args)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->MinTime(0.5);
  const int status = flatmarch::bench::run();
  std::filesystem::remove_all(scratch);
  return status;
}
