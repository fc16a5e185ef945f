// flatmarch: render flat surfaces by ray marching, and measure renderers against the truth.
#include <unistd.h>

#include <string>

#include "cli/commands.hpp"

int main(int argc, char** argv) {
  return flatmarch::cli::run(argc, argv, {flatmarch::cli::this_program(argv[0])});
}
