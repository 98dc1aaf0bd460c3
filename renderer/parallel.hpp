// The one parallel-for helper: image tiles or index ranges on a TBB arena with a fixed thread count.
// Work is split by position only, so results never depend on scheduling.
#pragma once

#include <algorithm>
#include <cstddef>

#include <tbb/blocked_range.h>
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace sb {

/// A rectangle of pixels [x0, x1) x [y0, y1).
struct PixelRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  [[nodiscard]] int width() const { return x1 - x0; }
  [[nodiscard]] int height() const { return y1 - y0; }
};

/// Runs parallel loops on `threads` threads (0 = all cores).
class Executor {
 public:
  explicit Executor(int threads = 0)
      : threads_(threads > 0 ? threads : tbb::this_task_arena::max_concurrency()), arena_(threads_) {}

  [[nodiscard]] int threads() const { return threads_; }

  /// Calls f(PixelRect) for every tile of a width x height image.
  template <class F>
  void for_tiles(int width, int height, int tile, F&& f) const {
    const int tx = (width + tile - 1) / tile, ty = (height + tile - 1) / tile;
    arena_.execute([&] {
      tbb::parallel_for(tbb::blocked_range<int>(0, tx * ty, 1), [&](const tbb::blocked_range<int>& r) {
        for (int t = r.begin(); t != r.end(); ++t) {
          const int x0 = (t % tx) * tile, y0 = (t / tx) * tile;
          f(PixelRect{x0, y0, std::min(x0 + tile, width), std::min(y0 + tile, height)});
        }
      });
    });
  }

  /// Calls f(begin, end) over [0, n) in chunks of at most `grain`.
  template <class F>
  void for_range(size_t n, size_t grain, F&& f) const {
    arena_.execute([&] {
      tbb::parallel_for(tbb::blocked_range<size_t>(0, n, std::max<size_t>(1, grain)),
                        [&](const tbb::blocked_range<size_t>& r) { f(r.begin(), r.end()); });
    });
  }

  /// Calls f(i) for every i in [0, n).
  template <class F>
  void for_each(size_t n, F&& f) const {
    for_range(n, 1, [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) f(i);
    });
  }

 private:
  int threads_;
  mutable tbb::task_arena arena_;
};

}  // namespace sb
