// The gate's one-sided Mann-Whitney U test on textbook cases, checked against the closed forms of
// complete separation and against SciPy 1.10 (scipy.stats.mannwhitneyu, alternative='greater').
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "validation/gate.hpp"

namespace sb::validation {
namespace {

TEST(RankTest, CompleteSeparationIsOneOverTheNumberOfOrderings) {
  // x above every y: U = m n, and only one of the C(m+n, m) orderings is that extreme.
  const std::vector<double> x3{4, 5, 6}, y3{1, 2, 3};
  RankTest r = mann_whitney_greater(x3, y3);
  EXPECT_TRUE(r.exact);
  EXPECT_DOUBLE_EQ(r.u, 9.0);
  EXPECT_NEAR(r.p, 1.0 / 20.0, 1e-15);
  const std::vector<double> x4{5, 6, 7, 8}, y4{1, 2, 3, 4};
  r = mann_whitney_greater(x4, y4);
  EXPECT_DOUBLE_EQ(r.u, 16.0);
  EXPECT_NEAR(r.p, 1.0 / 70.0, 1e-15);
  // The other direction: x below every y gives U = 0 and p = 1.
  r = mann_whitney_greater(y4, x4);
  EXPECT_DOUBLE_EQ(r.u, 0.0);
  EXPECT_NEAR(r.p, 1.0, 1e-15);
}

TEST(RankTest, ExactMatchesTextbookCase) {
  // Males/females example of the SciPy documentation (after Conover): U1 = 17, one-sided exact
  // p = 0.05555555555555555 (SciPy's two-sided 0.1111 halved).
  const std::vector<double> males{19, 22, 16, 29, 24}, females{20, 11, 17, 12};
  const RankTest r = mann_whitney_greater(males, females);
  EXPECT_TRUE(r.exact);
  EXPECT_DOUBLE_EQ(r.u, 17.0);
  EXPECT_NEAR(r.p, 0.05555555555555555, 1e-12);
}

TEST(RankTest, ExactForTimingLikeSamples) {
  // Ten against ten timings, no ties: SciPy exact p = 0.24062547359760988, U = 60.
  const std::vector<double> x{0.2, 0.21, 0.19, 0.22, 0.205, 0.195, 0.215, 0.185, 0.225, 0.2025};
  const std::vector<double> y{0.199, 0.207, 0.193, 0.211, 0.201, 0.197, 0.213, 0.189, 0.203, 0.191};
  const RankTest r = mann_whitney_greater(x, y);
  EXPECT_TRUE(r.exact);
  EXPECT_DOUBLE_EQ(r.u, 60.0);
  EXPECT_NEAR(r.p, 0.24062547359760988, 1e-12);
  // Twenty against twenty (the largest exact case, 40 values): SciPy exact p = 2.901777820769937e-11.
  const std::vector<double> x2{0.212, 0.205, 0.231, 0.219, 0.208, 0.226, 0.214, 0.221, 0.209, 0.217,
                               0.224, 0.211, 0.229, 0.207, 0.215, 0.222, 0.218, 0.213, 0.227, 0.210};
  const std::vector<double> y2{0.201,  0.198,  0.206,  0.2,    0.203,  0.196,  0.204,  0.199,  0.202,  0.197,
                               0.2055, 0.1995, 0.2035, 0.1975, 0.2015, 0.2045, 0.1985, 0.2025, 0.1965, 0.2005};
  const RankTest r2 = mann_whitney_greater(x2, y2);
  EXPECT_TRUE(r2.exact);
  EXPECT_DOUBLE_EQ(r2.u, 398.0);
  EXPECT_NEAR(r2.p / 2.901777820769937e-11, 1.0, 1e-9);
}

TEST(RankTest, NormalApproximationWithTies) {
  // Small samples with ties: SciPy 'asymptotic' (tie-corrected variance, continuity correction)
  // U = 32, p = 0.15962631485751094.
  const std::vector<double> x{1, 2, 2, 3, 3, 3, 4, 5}, y{1, 1, 2, 2, 3, 4};
  RankTest r = mann_whitney_greater(x, y);
  EXPECT_FALSE(r.exact);
  EXPECT_DOUBLE_EQ(r.u, 32.0);
  EXPECT_NEAR(r.p, 0.15962631485751094, 1e-12);
  // 25 against 25 (normal samples rounded to ms, three values tied across the samples):
  // SciPy asymptotic U = 467, p = 0.001401563439485108.
  const std::vector<double> a{1.1,   1.13,  1.073, 1.011, 1.055, 1.001, 1.106, 1.234, 1.051, 1.038, 1.149, 1.136, 1.111,
                              1.007, 1.097, 1.17,  0.966, 1.054, 0.91,  0.971, 0.916, 1.076, 0.973, 1.127, 1.116};
  const std::vector<double> b{0.981, 0.748, 0.946, 0.995, 1.011, 0.847, 0.952, 0.902, 0.919, 1.106, 0.919, 0.997, 1.088,
                              0.942, 0.989, 1.011, 1.006, 0.877, 1.008, 1.136, 0.845, 1.086, 1.012, 0.936, 1.2};
  r = mann_whitney_greater(a, b);
  EXPECT_FALSE(r.exact);
  EXPECT_DOUBLE_EQ(r.u, 467.0);
  EXPECT_NEAR(r.p, 0.001401563439485108, 1e-12);
}

TEST(RankTest, AllEqualAndEmptyGiveNoEvidence) {
  const std::vector<double> same{1, 1, 1}, none;
  EXPECT_DOUBLE_EQ(mann_whitney_greater(same, same).p, 1.0);
  EXPECT_DOUBLE_EQ(mann_whitney_greater(none, same).p, 1.0);
}

TEST(RankTest, Median) {
  EXPECT_DOUBLE_EQ(median({3, 1, 2}), 2.0);
  EXPECT_DOUBLE_EQ(median({4, 1, 3, 2}), 2.5);
  EXPECT_TRUE(std::isnan(median({})));
  // PSNRs, one of identical images: the finite middle value, not ∞ (which read as "identical").
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_DOUBLE_EQ(median({inf, 91.48}), 91.48);
  EXPECT_DOUBLE_EQ(median({30.0, inf, 40.0, inf}), 40.0);
  EXPECT_EQ(median({inf, inf}), inf);
  EXPECT_EQ(median({inf, 30.0, inf}), inf);
}

}  // namespace
}  // namespace sb::validation
