// The program caches' LruCache (backends/lru_cache.hpp): what it keeps, what it drops, and that a
// failed make leaves it as it was.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "backends/lru_cache.hpp"

namespace flatmarch {
namespace {

TEST(LruCache, KeepsUpToItsCapacityAndDropsTheLeastRecentlyUsed) {
  LruCache<std::string, int> cache(2);
  int made = 0;
  const auto make = [&] { return ++made; };
  EXPECT_EQ(cache.get("a", make), 1);
  EXPECT_EQ(cache.get("b", make), 2);
  EXPECT_EQ(cache.get("a", make), 1);  // kept: not made again, and now the most recent
  EXPECT_EQ(made, 2);
  EXPECT_EQ(cache.get("c", make), 3);  // full: drops b, the least recently used
  EXPECT_EQ(cache.size(), 2u);
  EXPECT_EQ(cache.get("a", make), 1);
  EXPECT_EQ(cache.get("b", make), 4);  // b was dropped, so made again (dropping c)
  EXPECT_EQ(cache.get("c", make), 5);
  EXPECT_EQ(made, 5);
}

TEST(LruCache, AMakeThatThrowsLeavesItAsItWas) {
  LruCache<std::string, int> cache(1);
  EXPECT_EQ(cache.get("a", [] { return 7; }), 7);
  EXPECT_THROW(cache.get("b", []() -> int { throw std::runtime_error("compile error"); }),
               std::runtime_error);
  EXPECT_EQ(cache.size(), 1u);
  EXPECT_EQ(cache.get("a", [] { return 8; }), 7);  // still kept
}

TEST(LruCache, ComparesKeysByItsEquality) {
  // Keys equal to a tolerance, as the viewer compares march parameters field by field.
  const auto near = [](double a, double b) { return std::abs(a - b) < 0.5; };
  LruCache<double, int, decltype(near)> cache(4, near);
  EXPECT_EQ(cache.get(1.0, [] { return 1; }), 1);
  EXPECT_EQ(cache.get(1.2, [] { return 2; }), 1);
  EXPECT_EQ(cache.get(3.0, [] { return 3; }), 3);
  cache.clear();
  EXPECT_EQ(cache.size(), 0u);
  EXPECT_EQ(cache.get(1.0, [] { return 4; }), 4);
}

}  // namespace
}  // namespace flatmarch
