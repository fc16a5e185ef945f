// Runs a program as a child process with a time limit and captures its output, for tests of the
// command line.
#pragma once

#include <string>
#include <vector>

#include "scene/geometry.hpp"

namespace flatmarch::test {

struct ProcessResult {
  int exit_code = -1;  // -1 when killed by a signal or timed out
  int signal = 0;
  bool timed_out = false;
  std::string out, err;
};

// argv[0] is found on PATH unless it is a path; throws std::runtime_error if it cannot be run.
ProcessResult run_process(const std::vector<std::string>& argv, double timeout_seconds = 60.0);

// Runs the flatmarch program under test with these arguments.
ProcessResult run_flatmarch(const std::vector<std::string>& args, double timeout_seconds = 60.0);

// A vector as a command-line argument X,Y,Z, with every digit a double has.
std::string vec3_arg(Vec3 v);

// A fresh empty directory under the system's temporary directory, removed with what it holds
// when the test program exits (unless FLATMARCH_KEEP_TEST_FILES is set and not 0).
std::string make_temp_dir();

}  // namespace flatmarch::test
