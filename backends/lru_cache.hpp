// A few costly things (compiled programs, pipelines) kept by key, the least recently used
// dropped first: the OpenGL and Vulkan backends' program caches and the viewer's.
#pragma once

#include <algorithm>
#include <cstddef>
#include <functional>
#include <utility>
#include <vector>

namespace flatmarch {

template <typename Key, typename Value, typename Equal = std::equal_to<Key>>
class LruCache {
 public:
  explicit LruCache(size_t capacity, Equal equal = {}) : capacity_(capacity), equal_(equal) {}

  // The value kept for `key`, or the one make() returns (kept, dropping the least recently used
  // when full; if make() throws, the cache is as it was). Either is then the most recently used.
  template <typename Make>
  Value& get(const Key& key, Make&& make) {
    auto it = std::find_if(entries_.begin(), entries_.end(),
                           [&](const auto& e) { return equal_(e.first, key); });
    if (it != entries_.end()) {
      std::rotate(it, it + 1, entries_.end());
    } else {
      Value made = std::forward<Make>(make)();
      if (entries_.size() >= capacity_) entries_.erase(entries_.begin());
      entries_.emplace_back(key, std::move(made));
    }
    return entries_.back().second;
  }

  void clear() { entries_.clear(); }
  size_t size() const { return entries_.size(); }

 private:
  size_t capacity_;
  Equal equal_;
  std::vector<std::pair<Key, Value>> entries_;  // least recently used first
};

}  // namespace flatmarch
