// gate.toml: strict keys (an unknown key names itself and its line), warn/fail consistency, rule
// cascading, turning checks off, and the shipped ci/gate.toml.
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "validation/gate.hpp"

namespace sb::validation {
namespace {

/// The message of the InputError that parsing `text` throws ("" when it parses).
std::string config_error(const std::string& text) {
  try {
    (void)parse_gate_config(text, "test.toml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(GateConfig, UnknownKeyIsRejectedWithNameAndLine) {
  const std::string in_defaults = config_error("[defaults]\nmin_psnr = 30\nmin_psnr_db = 31\n");
  EXPECT_NE(in_defaults.find("test.toml:3"), std::string::npos) << in_defaults;
  EXPECT_NE(in_defaults.find("'min_psnr_db'"), std::string::npos) << in_defaults;

  const std::string in_rule =
      config_error("[[rule]]\npipeline = \"repro-rt\"\n\n[[rule]]\nscene = \"spheres\"\nmax_holes = 0.1\n");
  EXPECT_NE(in_rule.find("test.toml:6"), std::string::npos) << in_rule;
  EXPECT_NE(in_rule.find("'max_holes'"), std::string::npos) << in_rule;

  const std::string in_regression = config_error("[regression]\ntolerance = 0.1\nrepetitions = 3\n");
  EXPECT_NE(in_regression.find("test.toml:3"), std::string::npos) << in_regression;
  EXPECT_NE(in_regression.find("'repetitions'"), std::string::npos) << in_regression;

  const std::string top = config_error("[default]\nmin_psnr = 30\n");
  EXPECT_NE(top.find("test.toml:1"), std::string::npos) << top;
  EXPECT_NE(top.find("'default'"), std::string::npos) << top;
}

TEST(GateConfig, AGlobThatCannotMeanWhatItSaysIsRejected) {
  // fnmatch reads an unclosed '[' as a literal '[': the rule would apply nowhere without a word.
  const std::string unclosed = config_error("[[rule]]\npipeline = \"[repro\"\nmin_psnr = 30\n");
  EXPECT_NE(unclosed.find("test.toml:2"), std::string::npos) << unclosed;
  EXPECT_NE(unclosed.find("[[rule]] pipeline = '[repro' is not a valid glob: the '[' at character 1 opens a set that "
                          "is never closed"),
            std::string::npos)
      << unclosed;
  const std::string lone = config_error("[[rule]]\nscene = 'spheres\\'\nmin_psnr = 30\n");
  EXPECT_NE(lone.find("ends in a lone '\\'"), std::string::npos) << lone;
  // Sets that are closed, escapes and a ']' first in a set are globs as meant.
  for (const char* glob : {"repro-[rt]*", "[!p]*", "[]x]", "a\\[b", "bidir-warp:occlusion=*"})
    EXPECT_EQ(config_error(fmt::format("[[rule]]\npipeline = '{}'\nmin_psnr = 30\n", glob)), "") << glob;
}

TEST(GateConfig, BadValuesAreRejected) {
  EXPECT_NE(config_error("[defaults]\nmin_psnr = \"high\"\n").find("test.toml:2"), std::string::npos);
  EXPECT_NE(config_error("[defaults]\nmin_psnr = -1\n").find("min_psnr"), std::string::npos);
  EXPECT_NE(config_error("[defaults]\nmin_psnr = true\n").find("false to turn the check off"), std::string::npos);
  EXPECT_NE(config_error("[regression]\nalpha = 1.5\n").find("alpha"), std::string::npos);
  EXPECT_NE(config_error("[regression]\nmin_repetitions = 2.5\n").find("min_repetitions"), std::string::npos);
  // The upper bound is said, with the value (it read "must be an integer of at least 1").
  EXPECT_NE(config_error("[regression]\nmin_repetitions = 1000000000000\n")
                .find("min_repetitions = 1000000000000 must be an integer from 1 to 1000000"),
            std::string::npos);
  // The value given is named, whatever its type.
  EXPECT_NE(config_error("[defaults]\nmin_psnr = \"30\"\n").find("min_psnr = \"30\" must be a number"),
            std::string::npos);
  EXPECT_NE(config_error("[defaults]\nmin_psnr = [30]\n").find("min_psnr = an array must be a number"),
            std::string::npos);
  EXPECT_NE(config_error("[regression]\ntolerance = \"x\"\n").find("[regression] tolerance = \"x\" must be"),
            std::string::npos);
  EXPECT_NE(config_error("[regression]\ntolerance = -0.5\n").find("[regression] tolerance = -0.5 must be"),
            std::string::npos);
  EXPECT_NE(config_error("rule = []\n").find("rule = [] holds no rule"), std::string::npos);
  EXPECT_NE(config_error("[[rule]]\npipeline = 3\n").find("pipeline"), std::string::npos);
  EXPECT_NE(config_error("rule = 1\n").find("[[rule]]"), std::string::npos);
  // A syntax error names the line and column.
  EXPECT_NE(config_error("[defaults]\nmin_psnr = = 3\n").find("test.toml:2:"), std::string::npos);
  // A warning level looser than the failure level of the same table.
  const std::string looser = config_error("[defaults]\nmin_psnr = 38\nwarn_psnr = 37\n");
  EXPECT_NE(looser.find("test.toml:3"), std::string::npos) << looser;
  EXPECT_NE(looser.find("warn_psnr"), std::string::npos) << looser;
  EXPECT_NE(config_error("[defaults]\nmax_hole_fraction = 0.1\nwarn_hole_fraction = 0.2\n").find("warn_hole_fraction"),
            std::string::npos);
  // Limits beyond what the metric can take: no cell could pass, or the limit could never be reached.
  const std::string ssim = config_error("[defaults]\nmin_ssim = 2\n");
  EXPECT_NE(ssim.find("test.toml:2: min_ssim = 2 is above 1, the largest SSIM; no cell could pass"), std::string::npos)
      << ssim;
  const std::string holes = config_error("[[rule]]\npipeline = \"repro-*\"\nmax_hole_fraction = 1.5\n");
  EXPECT_NE(holes.find("test.toml:3: max_hole_fraction = 1.5 is above 1"), std::string::npos) << holes;
  EXPECT_NE(config_error("[defaults]\nwarn_recall = 1.01\n").find("warn_recall"), std::string::npos);
  // Tables that give no limit a value pass anything, as an empty file would (both used to be accepted).
  for (const char* none : {"[[rule]]\npipeline = \"repro-*\"\n", "[defaults]\nmin_psnr = false\n",
                           "[defaults]\nmin_psnr = false\n[[rule]]\nregression_tolerance = false\n"})
    EXPECT_NE(config_error(none).find("sets no threshold, no [regression] and no rule's regression_tolerance"),
              std::string::npos)
        << none;
  EXPECT_NE(config_error("[defaults\nmin_psnr = 30\n").find("test.toml:1:10: not valid TOML: "), std::string::npos);
  EXPECT_NE(config_error("[defaults\nmin_psnr = 30\n").find("; mend the syntax there (the format: docs/gate.md)"),
            std::string::npos);
  // Limits no measure can cross pass anything too: PSNR of 8-bit images is at least 0 dB, a
  // fraction or a recall lies in [0, 1], a speed-up is above 0.
  for (const char* never : {"[defaults]\nmin_psnr = 0\n", "[defaults]\nmax_error_fraction = 1\nmax_hole_fraction = 1.0\n",
                            "[[rule]]\npipeline = \"repro-*\"\nmin_speedup = 0\nmin_recall = 0\nwarn_left_psnr = 0\n"}) {
    const std::string error = config_error(never);
    EXPECT_NE(error.find("sets no threshold that a measure can cross (only "), std::string::npos) << never << error;
  }
  EXPECT_NE(config_error("[[rule]]\npipeline = \"repro-*\"\nmin_speedup = 0\n")
                .find("(only min_speedup = 0 (the [[rule]] at line 1))"),
            std::string::npos);
  // Beside a limit that can fail, they are noted; SSIM can be negative, so min_ssim = 0 checks.
  const GateConfig mixed = parse_gate_config("[defaults]\nmin_psnr = 0\nmin_ssim = 0\n[[rule]]\nscene = \"x\"\n"
                                             "max_hole_fraction = 1\nmin_psnr = 30\n",
                                             "test.toml");
  EXPECT_EQ(mixed.vacuous, (std::vector<std::string>{"min_psnr = 0 ([defaults])",
                                                     "max_hole_fraction = 1 (the [[rule]] at line 4)"}));
  EXPECT_TRUE(parse_gate_config("[defaults]\nmin_ssim = 0\nmin_psnr = 0.01\nmax_hole_fraction = 0.999\n", "t")
                  .vacuous.empty());
  // A rule's regression_tolerance asks for the time regressions of its cells: a check.
  EXPECT_EQ(config_error("[defaults]\nmin_psnr = false\n[[rule]]\nregression_tolerance = 0.1\n"), "");
  // An integer beyond 2^53 is a number too: it was read through a conversion that gives none for
  // it, and the message said "min_psnr = -nan".
  EXPECT_EQ(config_error("[defaults]\nmin_psnr = 9007199254740993\n"), "");
  EXPECT_EQ(config_error("[regression]\ntolerance = 9007199254740993\n"), "");
  const std::string huge = config_error("[defaults]\nmax_error_fraction = 1000000000000000000\n");
  EXPECT_NE(huge.find("max_error_fraction = 1e+18 is above 1"), std::string::npos) << huge;
}

TEST(GateConfig, RulesOverrideDefaultsInFileOrder) {
  const GateConfig c = parse_gate_config(
      "[defaults]\nmin_psnr = 30\nmin_ssim = 0.9\n"
      "[regression]\ntolerance = 0.2\n"
      "[[rule]]\npipeline = \"repro-*\"\nmin_psnr = 35\n"
      "[[rule]]\npipeline = \"repro-rt\"\nscene = \"spheres\"\nmin_psnr = 38.2\nwarn_psnr = 39\nmin_ssim = false\n"
      "regression_tolerance = 0.3\n"
      "[[rule]]\ncell = \"*|640x360|*\"\nregression_tolerance = false\n",
      "test.toml");
  ASSERT_EQ(c.rules.size(), 3u);
  EXPECT_EQ(c.rules[1].line, 9);

  ThresholdValues t = thresholds_for(c, "repro-rt", "spheres", "spheres|e=0.064m|c=default|320x180|lights=all|full");
  EXPECT_EQ(t["min_psnr"], 38.2);
  EXPECT_EQ(t["warn_psnr"], 39.0);
  EXPECT_FALSE(t["min_ssim"].has_value());  // turned off
  EXPECT_EQ(t["regression_tolerance"], 0.3);

  t = thresholds_for(c, "repro-warp", "spheres", "x");
  EXPECT_EQ(t["min_psnr"], 35.0);
  EXPECT_EQ(t["min_ssim"], 0.9);
  EXPECT_EQ(t["regression_tolerance"], 0.2);

  t = thresholds_for(c, "plain-rt", "box-wall", "box-wall|e=0.064m|c=default|640x360|lights=all|full");
  EXPECT_EQ(t["min_psnr"], 30.0);
  EXPECT_FALSE(t["regression_tolerance"].has_value());
}

TEST(GateConfig, AWarningLevelLooserThanAFailureLevelFromAnotherTableIsNamed) {
  // Each table alone is consistent; merged for repro-rt on spheres, the rule's warn_psnr lies below
  // the defaults' min_psnr, so a PSNR of 27 fails without ever having warned.
  const GateConfig c = parse_gate_config(
      "[defaults]\nmin_psnr = 30\nmax_hole_fraction = 0.2\n"
      "[[rule]]\npipeline = \"repro-*\"\nwarn_psnr = 25\n"
      "[[rule]]\npipeline = \"repro-rt\"\nscene = \"box-wall\"\nmin_psnr = 20\n"
      "[[rule]]\npipeline = \"plain-rt\"\nwarn_hole_fraction = 0.3\nmin_psnr = false\n",
      "test.toml");
  const std::string cell = "spheres|e=0.064m|c=default|320x180|lights=all|full";
  const auto notes = [&](const std::string& pipeline, const std::string& scene) {
    std::map<std::string, std::string> origins;
    const ThresholdValues t = thresholds_for(c, pipeline, scene, cell, nullptr, &origins);
    return unreachable_warning_levels(t, origins, pipeline, scene);
  };
  std::vector<std::string> n = notes("repro-rt", "spheres");
  ASSERT_EQ(n.size(), 1u);
  EXPECT_EQ(n[0].find("for pipeline repro-rt on scene spheres, warn_psnr = 25 (the [[rule]] at line 4) is looser "
                      "than min_psnr = 30 ([defaults]): that warning can never be raised there"),
            0u)
      << n[0];
  // Where the later rule lowers the failure level below the warning, the levels are in order.
  EXPECT_TRUE(notes("repro-rt", "box-wall").empty());
  // A maximum: the rule's warning level above the defaults' failure level.
  n = notes("plain-rt", "spheres");
  ASSERT_EQ(n.size(), 1u);
  EXPECT_NE(n[0].find("warn_hole_fraction = 0.3 (the [[rule]] at line 11) is looser than max_hole_fraction = 0.2 "
                      "([defaults])"),
            std::string::npos)
      << n[0];
  // A pipeline no rule matches keeps the defaults alone.
  EXPECT_TRUE(notes("rt-atomic", "spheres").empty());
}

TEST(GateConfig, ShippedConfigParses) {
  const GateConfig c = load_gate_config(std::filesystem::path(SB_SOURCE_DIR) / "ci" / "gate.toml");
  EXPECT_FALSE(c.rules.empty());
  EXPECT_DOUBLE_EQ(c.regression.tolerance, 0.10);
  EXPECT_DOUBLE_EQ(c.regression.alpha, 0.05);
  EXPECT_EQ(c.regression.min_repetitions, 3);
  // The smoke scene's repro-rt thresholds (measured 48.34 dB at 320x180, e = 0.064 m).
  ThresholdValues t = thresholds_for(c, "repro-rt", "box-wall", "box-wall|e=0.064m|c=default|320x180|lights=all|full");
  EXPECT_EQ(t["min_psnr"], 46.0);
  EXPECT_EQ(t["min_recall"], 0.99);
  EXPECT_EQ(t["max_hole_fraction"], 0.03);
  // The smoke sweep's scene: spheres rules (repro-rt measured 32.65 / 33.87 dB in the two cells).
  t = thresholds_for(c, "repro-rt", "spheres", "spheres|e=0.12m|c=default|320x180|lights=all|full");
  EXPECT_EQ(t["min_psnr"], 30.6);
  EXPECT_EQ(t["max_hole_fraction"], 0.32);
}

}  // namespace
}  // namespace sb::validation
