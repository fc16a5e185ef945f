// The test programs' faulty backend (tests/backends/faulty.cpp): FLATMARCH_FAULTY's parsing, and
// that each fault does what it says — a wrong frame conformance fails, a crash, an abort, a hang,
// an allocation without bound — since the tests of isolation, resumption and the gate rely on it.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <stdexcept>

#include "backends/backend.hpp"
#include "backends/scalar/scalar.hpp"
#include "conformance/suite.hpp"
#include "tests/backends/faults.hpp"
#include "tests/gallery.hpp"

namespace flatmarch::test {
namespace {

// FLATMARCH_FAULTY set for one test.
class Faults : public testing::Test {
 protected:
  void TearDown() override { unsetenv("FLATMARCH_FAULTY"); }
  static void ask(const char* faults) { setenv("FLATMARCH_FAULTY", faults, 1); }
  static std::unique_ptr<Backend> faulty() { return make_backend("faulty", {}); }
};

TEST(FaultList, ParsesFaultsScenesAndSeconds) {
  const std::vector<Fault> f =
      parse_faults("crash=torus,hang,sleep:0.25=cube,flip,abort=torus/sphere");
  ASSERT_EQ(f.size(), 5u);
  EXPECT_EQ(f[0].kind, Fault::Kind::crash);
  EXPECT_EQ(f[0].scene, "torus");
  EXPECT_EQ(f[1].kind, Fault::Kind::hang);
  EXPECT_EQ(f[1].scene, "");
  EXPECT_EQ(f[2].kind, Fault::Kind::sleep);
  EXPECT_EQ(f[2].scene, "cube");
  EXPECT_EQ(f[2].seconds, 0.25);
  EXPECT_EQ(f[4].scene, "torus");
  EXPECT_EQ(f[4].method, "sphere");
  EXPECT_TRUE(parse_faults("").empty());
  // The fault naming a scene comes first; one naming none applies where none names the scene.
  EXPECT_EQ(fault_for(f, "torus", "analytic")->kind, Fault::Kind::crash);
  EXPECT_EQ(fault_for(f, "torus", "sphere")->kind, Fault::Kind::abort);
  EXPECT_EQ(fault_for(f, "cube", "sphere")->kind, Fault::Kind::sleep);
  EXPECT_EQ(fault_for(f, "l_shape", "sphere")->kind, Fault::Kind::hang);
  EXPECT_FALSE(fault_for(parse_faults("nan=cube"), "torus", "sphere").has_value());
}

TEST(FaultList, RefusesWhatItCannotAct) {
  for (const char* bad : {"boom", "crash=", "sleep", "sleep:x", "sleep:-1", "sleep:1e9", "crash:2",
                          ",", "nan,,flip", "crash=torus/"})
    EXPECT_THROW(parse_faults(bad), std::invalid_argument) << bad;
  try {
    parse_faults("explode=torus");
    FAIL() << "an unknown fault was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown fault 'explode'"), std::string::npos) << e.what();
  }
}

TEST_F(Faults, AnUnreadableListMakesTheBackendUnavailableWithTheReason) {
  ask("explode");
  const Availability a = faulty()->availability();
  EXPECT_FALSE(a.available);
  EXPECT_NE(a.reason.find("FLATMARCH_FAULTY"), std::string::npos) << a.reason;
}

TEST_F(Faults, ByDefaultFramesAreBlankAndTracesEmpty) {
  const Scene& scene = gallery_scene("l_shape");
  const Frame f = faulty()->render(scene, scene.camera, 8, 4, {}, {});
  ASSERT_EQ(f.width, 8);
  for (size_t px = 0; px < 32; ++px) {
    EXPECT_EQ(f.hit[px], static_cast<float>(kHitMiss));
    EXPECT_EQ(f.steps[px], 0.0f);
    EXPECT_EQ(f.t[px], 0.0f);
    EXPECT_EQ(f.rgb[3 * px], 0.0f);
  }
  EXPECT_TRUE(faulty()->trace(scene, Ray{}, {}, 16).events.empty());
}

// A backend that runs and is wrong fails conformance: blank, NaN and upside-down frames alike.
TEST_F(Faults, ConformanceFailsEveryWrongFrame) {
  const Scene& scene = gallery_scene("l_shape");
  for (const char* faults : {"", "nan", "flip=l_shape"}) {
    ask(faults);
    conformance::Suite suite;
    const conformance::CaseResult r = suite.run(*faulty(), scene, {}, 64, 36);
    EXPECT_EQ(r.verdict, conformance::Verdict::fail) << "FLATMARCH_FAULTY=" << faults;
  }
}

TEST_F(Faults, FlipAndSleepAreTheScalarFrameTurnedOrLate) {
  const Scene& scene = gallery_scene("l_shape");
  const Frame right = ScalarBackend().render(scene, scene.camera, 6, 5, {}, {});
  ask("flip");
  const Frame flipped = faulty()->render(scene, scene.camera, 6, 5, {}, {});
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 6; ++i) {
      EXPECT_EQ(flipped.steps[flipped.pixel(i, j)], right.steps[right.pixel(i, 4 - j)]);
      EXPECT_EQ(flipped.t[flipped.pixel(i, j)], right.t[right.pixel(i, 4 - j)]);
    }
  ask("sleep:0.05");
  const Frame late = faulty()->render(scene, scene.camera, 6, 5, {}, {});
  EXPECT_EQ(late.t, right.t);
  EXPECT_EQ(late.rgb, right.rgb);
}

// The faults that end or stall the process, each in a child (a death test).
#ifdef FLATMARCH_SANITIZE_BUILD
#define SKIP_UNDER_SANITIZERS() \
  GTEST_SKIP() << "a sanitizer catches the signal and the address-space limit"
#else
#define SKIP_UNDER_SANITIZERS()
#endif

TEST_F(Faults, CrashAbortAndHangEndOrStallTheProcess) {
  SKIP_UNDER_SANITIZERS();
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const Scene& scene = gallery_scene("l_shape");
  const auto render = [&](const char* faults) {
    ask(faults);
    faulty()->render(scene, scene.camera, 4, 4, {}, {});
  };
  EXPECT_EXIT(render("crash=l_shape"), testing::KilledBySignal(SIGSEGV), "");
  EXPECT_EXIT(render("abort"), testing::KilledBySignal(SIGABRT), "");
  // A hang outlasts an alarm two seconds away.
  EXPECT_EXIT(
      {
        alarm(2);
        render("hang");
      },
      testing::KilledBySignal(SIGALRM), "");
  // A fault for another scene leaves this one's frame blank.
  ask("crash=torus");
  EXPECT_EQ(faulty()->render(scene, scene.camera, 4, 4, {}, {}).steps[0], 0.0f);
}

TEST_F(Faults, OomAllocatesUntilRefused) {
  SKIP_UNDER_SANITIZERS();
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const Scene& scene = gallery_scene("l_shape");
  const auto exhaust = [&] {
    constexpr rlim_t kLimit = rlim_t{2} << 30;  // 2 GiB of address space
    const rlimit limit{kLimit, kLimit};
    setrlimit(RLIMIT_AS, &limit);
    ask("oom");
    try {
      faulty()->render(scene, scene.camera, 4, 4, {}, {});
    } catch (const std::bad_alloc&) {
      std::_Exit(42);
    }
  };
  EXPECT_EXIT(exhaust(), testing::ExitedWithCode(42), "");
}

}  // namespace
}  // namespace flatmarch::test
