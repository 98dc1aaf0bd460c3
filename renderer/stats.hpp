// Per-stage wall-clock timings and named counters that every pipeline reports (DESIGN §8).
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace sb {

/// Which eye a stage's work is for. A reprojecting pipeline renders its left eye and synthesizes
/// its right from it, so what its right eye costs beside its left is its whole point; a stage whose
/// work serves both eyes at once (a shared pass, a scan-line loop that traces the left eye and
/// reprojects into the right as it goes) belongs to neither.
enum class StageEye : uint8_t { left, right, both };

/// "left", "right" or "both".
[[nodiscard]] inline const char* stage_eye_name(StageEye eye) {
  return eye == StageEye::left ? "left" : eye == StageEye::right ? "right" : "both";
}

/// One timed stage: its name, its seconds so far, and the eye its work serves.
struct StageTime {
  std::string name;
  double seconds = 0.0;
  StageEye eye = StageEye::both;
};

/// Named stage timings in the order the stages started, each with the eye it serves; a repeated name
/// accumulates (and must name the same eye).
class Timings {
 public:
  void add(const std::string& stage, double seconds, StageEye eye) {
    for (StageTime& s : stages_)
      if (s.name == stage) {
        if (s.eye != eye)
          throw std::logic_error("stage '" + stage + "' timed for the " + stage_eye_name(s.eye) + " eye and for the " +
                                 stage_eye_name(eye) + " eye");
        s.seconds += seconds;
        return;
      }
    stages_.push_back({stage, seconds, eye});
  }
  [[nodiscard]] double get(const std::string& stage) const {
    for (const StageTime& s : stages_)
      if (s.name == stage) return s.seconds;
    return 0.0;
  }
  [[nodiscard]] double total() const {
    double t = 0.0;
    for (const StageTime& s : stages_) t += s.seconds;
    return t;
  }
  [[nodiscard]] const std::vector<StageTime>& stages() const { return stages_; }

  /// Seconds of the stages that serve `eye`.
  [[nodiscard]] double eye_total(StageEye eye) const {
    double t = 0.0;
    for (const StageTime& s : stages_)
      if (s.eye == eye) t += s.seconds;
    return t;
  }
  /// The stages that serve both eyes, in order: their time belongs to neither eye's share.
  [[nodiscard]] std::vector<std::string> shared_stages() const {
    std::vector<std::string> out;
    for (const StageTime& s : stages_)
      if (s.eye == StageEye::both) out.push_back(s.name);
    return out;
  }

 private:
  std::vector<StageTime> stages_;
};

/// Times a scope into a Timings entry for the stage `stage`, which serves `eye`.
class ScopedStage {
 public:
  /// Enters the stage at once (in the order stages start), so that a stage named before for the
  /// other eye throws here rather than in the destructor.
  ScopedStage(Timings& timings, std::string stage, StageEye eye) : timings_(timings), stage_(std::move(stage)), eye_(eye) {
    timings_.add(stage_, 0.0, eye_);
    start_ = std::chrono::steady_clock::now();
  }
  ~ScopedStage() {
    timings_.add(stage_, std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(), eye_);
  }
  ScopedStage(const ScopedStage&) = delete;
  ScopedStage& operator=(const ScopedStage&) = delete;

 private:
  Timings& timings_;
  std::string stage_;
  StageEye eye_;
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
