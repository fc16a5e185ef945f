#include "motion/settings.hpp"

#include <algorithm>
#include <cmath>

namespace flatmarch::motion {

namespace {

double quarter_decades(double start, int steps) {
  return start * std::pow(10.0, steps / 4.0);
}

}  // namespace

MarchParams MarchSettings::params() const {
  MarchParams p = start_;
  p.eps = quarter_decades(start_.eps, eps_steps_);
  p.offset = quarter_decades(start_.offset, offset_steps_);
  return p;
}

bool MarchSettings::step_eps(int steps) {
  const double eps = quarter_decades(start_.eps, eps_steps_ + steps);
  if (eps < kMinEps || eps > kMaxEps) return false;
  eps_steps_ += steps;
  // Offset follows eps up; eps <= kMaxEps < kMaxOffset, so a few steps suffice.
  for (int k = 0; k < 64 && params().offset <= eps; ++k) ++offset_steps_;
  return true;
}

bool MarchSettings::step_offset(int steps) {
  const double offset = quarter_decades(start_.offset, offset_steps_ + steps);
  if (offset <= params().eps || offset > kMaxOffset) return false;
  offset_steps_ += steps;
  return true;
}

double RenderScale::value() const {
  return std::clamp(start_ * std::pow(2.0, steps_ / 2.0), kMinScale, kMaxScale);
}

bool RenderScale::step(int steps) {
  const double before = value();
  steps_ += steps;
  if (value() != before) return true;
  steps_ -= steps;  // at a bound already
  return false;
}

}  // namespace flatmarch::motion
