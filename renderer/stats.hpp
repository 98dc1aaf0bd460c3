// Per-stage wall-clock timings and named counters that every pipeline reports (DESIGN §8).
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace sb {

/// Named stage timings in the order the stages ran; a repeated name accumulates.
class Timings {
 public:
  void add(const std::string& stage, double seconds) {
    for (auto& [name, s] : stages_)
      if (name == stage) {
        s += seconds;
        return;
      }
    stages_.emplace_back(stage, seconds);
  }
  [[nodiscard]] double get(const std::string& stage) const {
    for (const auto& [name, s] : stages_)
      if (name == stage) return s;
    return 0.0;
  }
  [[nodiscard]] double total() const {
    double t = 0.0;
    for (const auto& [name, s] : stages_) t += s;
    return t;
  }
  [[nodiscard]] const std::vector<std::pair<std::string, double>>& stages() const { return stages_; }

 private:
  std::vector<std::pair<std::string, double>> stages_;
};

/// Times a scope into a Timings entry.
class ScopedStage {
 public:
  ScopedStage(Timings& timings, std::string stage)
      : timings_(timings), stage_(std::move(stage)), start_(std::chrono::steady_clock::now()) {}
  ~ScopedStage() {
    timings_.add(stage_, std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count());
  }
  ScopedStage(const ScopedStage&) = delete;
  ScopedStage& operator=(const ScopedStage&) = delete;

 private:
  Timings& timings_;
  std::string stage_;
  std::chrono::steady_clock::time_point start_;
};

/// Named event counters (rays by kind, pixels shaded, triangles rasterized, ...). Thread-safe;
/// hot loops count locally and add once per tile.
class Counters {
 public:
  Counters() = default;
  Counters(const Counters& o) : values_(o.snapshot()) {}
  Counters& operator=(const Counters& o) {
    if (this != &o) {
      auto v = o.snapshot();
      std::lock_guard lock(mutex_);
      values_ = std::move(v);
    }
    return *this;
  }
  void add(const std::string& name, uint64_t value) {
    std::lock_guard lock(mutex_);
    values_[name] += value;
  }
  void set(const std::string& name, uint64_t value) {
    std::lock_guard lock(mutex_);
    values_[name] = value;
  }
  [[nodiscard]] uint64_t get(const std::string& name) const {
    std::lock_guard lock(mutex_);
    auto it = values_.find(name);
    return it == values_.end() ? 0 : it->second;
  }
  [[nodiscard]] std::map<std::string, uint64_t> snapshot() const {
    std::lock_guard lock(mutex_);
    return values_;
  }
  void merge(const Counters& o) {
    for (const auto& [k, v] : o.snapshot()) add(k, v);
  }

 private:
  mutable std::mutex mutex_;
  std::map<std::string, uint64_t> values_;
};

}  // namespace sb
