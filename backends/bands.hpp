// The bands of rows a GPU backend draws a frame in, where it needs any: so that progress can be
// reported, or so that no single draw or dispatch runs long on a GPU (a driver's watchdog ends one
// after a second or two where the GPU drives a display), yet in as few bands as that allows, for
// every band is a submission the host waits for, and waits for the last of its pixels (on a
// software rasteriser, for the slowest of its threads). Where neither applies (a software
// rasteriser, no progress asked for) a frame is one submission.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

namespace flatmarch {

// Why a frame is cut into bands.
enum class Banding {
  progress,  // progress is asked for: a band about every BandPacer::kBandSeconds
  watchdog,  // a GPU: no band longer than BandPacer::kWatchdogSeconds at the measured pace
  none,      // a software rasteriser and no progress: the whole frame in one submission
};
inline Banding banding(bool progress, bool software_device) {
  return progress ? Banding::progress : software_device ? Banding::none : Banding::watchdog;
}

class BandPacer {
 public:
  // About how long one band should take where progress is asked for, and at most where a GPU
  // driver's watchdog may apply (a tenth of the shortest one known, 2 s).
  static constexpr double kBandSeconds = 0.1;
  static constexpr double kWatchdogSeconds = 0.2;
  // The first band of a frame whose pace is not known yet, and how much larger than the one
  // before each later band of it may be.
  static constexpr int kFirstBandRows = 64;
  static constexpr int kGrowth = 4;

  // `last_pace`: the slowest seconds per pixel of the program's last frame, 0 if it has drawn
  // none (or none in bands). Bands are multiples of `granule` rows (a compute tile), the last one
  // excepted.
  BandPacer(double last_pace, int width, int height, int granule = 1,
            Banding why = Banding::progress)
      : last_pace_(last_pace),
        width_(width),
        height_(height),
        granule_(std::max(granule, 1)),
        budget_(why == Banding::progress   ? kBandSeconds
                : why == Banding::watchdog ? kWatchdogSeconds
                                           : std::numeric_limits<double>::infinity()) {}

  // The rows of the band that starts at `row`: the budget's worth (kBandSeconds or
  // kWatchdogSeconds; with Banding::none, the rest of the frame) at the last frame's pace, or in
  // a first frame at the pace of its bands so far but the first (a driver may compile the program
  // at its first draw), growing at most kGrowth-fold a band.
  int rows(int row) const {
    if (std::isinf(budget_)) return height_ - row;
    const double pace = last_pace_ > 0.0 ? last_pace_ : slowest_;
    const double grown = previous_ > 0 ? static_cast<double>(kGrowth) * previous_ : kFirstBandRows;
    double wanted = pace > 0.0 ? budget_ / (pace * width_) : grown;
    if (last_pace_ <= 0.0) wanted = std::min(wanted, grown);
    const double rounded = std::max(1.0, std::floor(wanted / granule_)) * granule_;
    return static_cast<int>(std::min(rounded, static_cast<double>(height_ - row)));
  }

  // A band of `rows` rows took `seconds`.
  void done(int rows, double seconds) {
    if (last_pace_ > 0.0 || bands_ > 0)
      slowest_ = std::max(slowest_, seconds / (static_cast<double>(rows) * width_));
    previous_ = rows;
    ++bands_;
  }

  // The pace to keep for the program's next frame: this frame's slowest, or the last frame's if
  // this one told nothing (one band, its first).
  double pace() const { return slowest_ > 0.0 ? slowest_ : last_pace_; }

 private:
  double last_pace_;
  int width_, height_, granule_;
  double budget_;  // seconds a band
  double slowest_ = 0.0;
  int previous_ = 0, bands_ = 0;
};

}  // namespace flatmarch
