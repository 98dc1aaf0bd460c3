// Results lines for gate tests, written the way `stereobench sweep` writes them (docs/sweeps.md),
// with chosen metric values and timing samples.
#pragma once

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/image_metrics.hpp"

namespace sb::test {

/// The numbers of one pipeline in a cell.
struct FakePipeline {
  std::string name;
  double psnr = 45.0;
  double ssim = 0.998;
  double error_fraction = 0.001;
  double hole_fraction = 0.01;
  double recall = 1.0;
  double speedup = 2.0;
  double right_over_left = 0.15;  ///< the right eye's time over the left eye's
  std::vector<double> samples_s{0.010, 0.011, 0.012};
};

/// Sets the PSNR of a record's metrics (a number, "inf" or null) and the MSE it comes from.
inline void set_psnr(nlohmann::json& metrics, const nlohmann::json& psnr) {
  metrics["psnr"] = psnr;
  metrics["mse"] = psnr.is_number() ? nlohmann::json(mse_of_psnr(psnr.get<double>()))
                   : psnr == "inf"  ? nlohmann::json(0.0)
                                    : nlohmann::json(nullptr);
}

/// A pipeline entry: a validation record holding the fields the gate reads, and timing.
inline nlohmann::json fake_entry(const FakePipeline& p) {
  nlohmann::json v = {
      {"kind", "stereobench.validation"},
      {"schema_version", 1},
      {"pipeline", p.name},
      {"options", nlohmann::json::object()},
      {"metrics",
       {{"psnr", p.psnr}, {"ssim", p.ssim}, {"mse", mse_of_psnr(p.psnr)}, {"error_fraction", p.error_fraction}, {"error_threshold", 2}}},
      {"holes", {{"hole_fraction", p.hole_fraction}, {"not_reprojected", {{"recall", p.recall}}}}}};
  std::vector<double> sorted = p.samples_s;
  std::sort(sorted.begin(), sorted.end());
  return {{"validation", v},
          {"timing",
           {{"repetitions", p.samples_s.size()},
            {"warmup", 0},
            {"median_s", sorted[sorted.size() / 2]},
            {"samples_s", p.samples_s},
            {"speedup_median", p.speedup},
            {"right_over_left_median", p.right_over_left}}}};
}

/// A whole results line of a cell of box-wall at 320x180 with interaxial `e`.
inline nlohmann::json fake_cell(int index, double e, const std::vector<FakePipeline>& pipelines,
                                const std::string& scene = "box-wall") {
  nlohmann::json pipes = nlohmann::json::object();
  for (const FakePipeline& p : pipelines) pipes[p.name] = fake_entry(p);
  return {{"kind", "stereobench.sweep_cell"},
          {"schema_version", 1},
          {"sweep", "test"},
          {"cell_id", scene + "|e=" + nlohmann::json(e).dump() + "m|c=default|320x180|lights=all|full"},
          {"cell_index", index},
          {"cell_count", 2},
          {"cell",
           {{"scene", scene},
            {"scene_params", nlohmann::json::object()},
            {"interaxial_m", e},
            {"max_disparity_px", nullptr},
            {"convergence_m", nullptr},
            {"resolution", "320x180"},
            {"lights", nullptr},
            {"truth", "full"}}},
          {"rig",
           {{"width", 320}, {"height", 180}, {"interaxial_m", e}, {"convergence_m", 2.0}, {"max_disparity_px", 9.5}}},
          {"baseline", "plain-rt"},
          {"pipelines", pipes},
          {"host", "testhost"},
          {"finished", "2026-11-21T19:20:00Z"}};
}

/// Writes cells as JSON Lines.
inline void write_results(const std::filesystem::path& file, const std::vector<nlohmann::json>& cells) {
  std::ofstream out(file, std::ios::binary);
  for (const nlohmann::json& c : cells) out << c.dump() << '\n';
}

/// Writes text to a file.
inline void write_file(const std::filesystem::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
}

}  // namespace sb::test
