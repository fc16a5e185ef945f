// The SIMD backend's tuning table (backends/simd/tuning.hpp) and the probe that overrides it for
// measuring (FLATMARCH_SIMD_TUNE, compiled in with FLATMARCH_SIMD_TUNING_PROBE: this program
// builds tuning.cpp so, the shipped backend does not read the environment).
#include <gtest/gtest.h>

#include <cstdlib>
#include <stdexcept>

#include "backends/simd/tuning.hpp"

namespace flatmarch::simd {
namespace {

struct Environment {
  explicit Environment(const char* value) { setenv("FLATMARCH_SIMD_TUNE", value, 1); }
  ~Environment() { unsetenv("FLATMARCH_SIMD_TUNE"); }
};

TEST(Tuning, WithoutTheVariableEachInstructionSetTakesItsRow) {
  unsetenv("FLATMARCH_SIMD_TUNE");
  for (Isa isa : {Isa::avx512, Isa::avx2, Isa::sse4}) {
    const Tuning t = tuning(isa), row = kTunings[static_cast<size_t>(isa)];
    EXPECT_EQ(t.refill_at, row.refill_at) << isa_name(isa);
    EXPECT_EQ(t.most_vectors, row.most_vectors) << isa_name(isa);
    EXPECT_EQ(t.modes, row.modes) << isa_name(isa);
    // Eighths of the lanes, and at least one vector.
    EXPECT_GE(row.refill_at, 1);
    EXPECT_LE(row.refill_at, 8);
    EXPECT_LE(row.refill_spread, 8);
    EXPECT_GE(row.most_vectors, 1);
  }
}

TEST(Tuning, TheProbeOverridesEveryOrOneInstructionSet) {
  const Environment e(
      "refill_at=5,avx2.most_vectors=3,sse4.nearest_line=1,patience=8,avx512.rooms_per_pass=2,"
      "held=0,avx512.by_slot=0");
  EXPECT_EQ(tuning(Isa::avx512).refill_at, 5);
  EXPECT_EQ(tuning(Isa::sse4).refill_at, 5);
  EXPECT_EQ(tuning(Isa::avx2).most_vectors, 3);
  EXPECT_EQ(tuning(Isa::avx512).most_vectors, kTunings[0].most_vectors);
  EXPECT_TRUE(tuning(Isa::sse4).takes(kModeNearestLine));
  EXPECT_FALSE(kTunings[2].takes(kModeNearestLine));
  // A mode off, on every instruction set or one; the others as their rows have them.
  for (Isa isa : {Isa::avx512, Isa::avx2, Isa::sse4}) {
    const Tuning t = tuning(isa), row = kTunings[static_cast<size_t>(isa)];
    EXPECT_FALSE(t.takes(kModeHeld)) << isa_name(isa);
    EXPECT_EQ(t.takes(kModeBySlot), isa != Isa::avx512 && row.takes(kModeBySlot)) << isa_name(isa);
    EXPECT_EQ(t.takes(kModeWhole), row.takes(kModeWhole)) << isa_name(isa);
  }
  EXPECT_EQ(tuning(Isa::avx2).patience, 8);
  EXPECT_EQ(tuning(Isa::avx2).patience_two_rooms, kTunings[1].patience_two_rooms);
  EXPECT_EQ(tuning(Isa::avx512).rooms_per_pass, 2);
  EXPECT_EQ(tuning(Isa::avx2).rooms_per_pass, kTunings[1].rooms_per_pass);
}

TEST(Tuning, TheProbeRefusesWhatItDoesNotKnow) {
  {
    const Environment e("bogus=1");
    EXPECT_THROW(tuning(Isa::avx2), std::invalid_argument);
  }
  {
    const Environment e("refill_at");
    EXPECT_THROW(tuning(Isa::avx2), std::invalid_argument);
  }
  for (const char* text : {"refill_at=five", "refill_at=5x", "refill_at=", "avx9.refill_at=5"}) {
    const Environment e(text);
    EXPECT_THROW(tuning(Isa::avx2), std::invalid_argument) << text;
  }
}

}  // namespace
}  // namespace flatmarch::simd
