// BandPacer: how a GPU backend cuts a frame into bands of rows (backends/bands.hpp).
#include "backends/bands.hpp"

#include <gtest/gtest.h>

namespace flatmarch {
namespace {

TEST(Bands, AFirstFrameStartsSmallAndGrowsAtMostFourfoldABand) {
  BandPacer bands(0.0, 100, 1000);
  EXPECT_EQ(bands.rows(0), 64);
  bands.done(64, 10.0);  // the first band may compile the program: its time tells nothing
  EXPECT_EQ(bands.rows(64), 256);
  bands.done(256, 256 * 100 * 1e-7);  // 0.1 us a pixel: 0.1 s would be 10000 rows
  EXPECT_EQ(bands.rows(320), 680);    // 4 x 256 = 1024, cut to what is left
  EXPECT_DOUBLE_EQ(bands.pace(), 1e-7);
}

TEST(Bands, AFrameAfterTheFirstTakesATenthOfASecondABandAtTheLastFramesPace) {
  BandPacer bands(1e-6, 100, 5000);  // 100 pixels a row at 1 us: 1000 rows in 0.1 s
  EXPECT_EQ(bands.rows(0), 1000);
  bands.done(1000, 0.1);
  bands.done(1000, 0.2);  // a slower band: the next frame goes by the slowest
  EXPECT_EQ(bands.rows(4500), 500);
  EXPECT_DOUBLE_EQ(bands.pace(), 2e-6);
  EXPECT_EQ(BandPacer(1e-9, 100, 300).rows(0), 300);  // fast enough: the whole frame at once
}

TEST(Bands, BandsAreWholeTilesAndNeverEmpty) {
  EXPECT_EQ(BandPacer(1e-6, 100, 5000, 16).rows(0), 992);  // 1000 rows down to 62 tiles
  EXPECT_EQ(BandPacer(1.0, 100, 5000, 16).rows(0), 16);    // slower than 0.1 s a row: one tile
  EXPECT_EQ(BandPacer(1.0, 100, 5000).rows(0), 1);
  EXPECT_EQ(BandPacer(1e-6, 100, 5000, 16).rows(4990), 10);  // the last band: what is left
}

TEST(Bands, AOneBandFirstFrameKeepsThePaceUnknown) {
  BandPacer bands(0.0, 10, 20);
  EXPECT_EQ(bands.rows(0), 20);
  bands.done(20, 1.0);
  EXPECT_DOUBLE_EQ(bands.pace(), 0.0);
}

TEST(Bands, OnlyProgressOrAGpusWatchdogCutsAFrame) {
  EXPECT_EQ(banding(true, true), Banding::progress);
  EXPECT_EQ(banding(true, false), Banding::progress);
  EXPECT_EQ(banding(false, false), Banding::watchdog);
  EXPECT_EQ(banding(false, true), Banding::none);
  // A software rasteriser without progress: one submission, first frame or not.
  EXPECT_EQ(BandPacer(0.0, 100, 5000, 8, Banding::none).rows(0), 5000);
  EXPECT_EQ(BandPacer(1.0, 100, 5000, 8, Banding::none).rows(16), 4984);
  // A GPU: bands of at most 0.2 s at the last frame's pace (2000 rows of 100 pixels at 1 us),
  // and a first frame starting small, as with progress.
  EXPECT_EQ(BandPacer(1e-6, 100, 5000, 8, Banding::watchdog).rows(0), 2000);
  EXPECT_EQ(BandPacer(1e-9, 100, 5000, 8, Banding::watchdog).rows(0), 5000);
  EXPECT_EQ(BandPacer(0.0, 100, 5000, 8, Banding::watchdog).rows(0), 64);
}

}  // namespace
}  // namespace flatmarch
