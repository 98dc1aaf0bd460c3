// The memory check: the budget is the tightest bound the system reports (plus the heap's reusable
// free memory), and work beyond the usable share of it is refused with a ResourceError that says
// what needed how much, which bound is in the way and what to do.
#include <gtest/gtest.h>

#include <string>

#include "renderer/error.hpp"
#include "renderer/memory.hpp"

namespace sb {
namespace {

constexpr uint64_t kGiB = uint64_t{1} << 30;

TEST(Memory, TheBudgetIsTheTightestBoundPlusTheHeapsFreeMemory) {
  MemorySources s;
  EXPECT_EQ(memory_budget(s).bytes, UINT64_MAX) << "no bound read: no limit";
  EXPECT_TRUE(memory_budget(s).bound.empty());

  s.mem_available = 20 * kGiB;
  EXPECT_EQ(memory_budget(s).bytes, 20 * kGiB);
  EXPECT_NE(memory_budget(s).bound.find("MemAvailable"), std::string::npos);

  // A cgroup limit counts what the group already uses.
  s.cgroup_limit = 16 * kGiB;
  s.cgroup_usage = 6 * kGiB;
  s.cgroup_file = "/sys/fs/cgroup/memory.max";
  EXPECT_EQ(memory_budget(s).bytes, 10 * kGiB);
  EXPECT_NE(memory_budget(s).bound.find("/sys/fs/cgroup/memory.max"), std::string::npos) << memory_budget(s).bound;

  // An address-space limit counts the process's whole virtual size; one already exceeded leaves 0.
  s.address_limit = 4 * kGiB;
  s.address_used = 1 * kGiB;
  EXPECT_EQ(memory_budget(s).bytes, 3 * kGiB);
  EXPECT_NE(memory_budget(s).bound.find("ulimit -v"), std::string::npos) << memory_budget(s).bound;
  s.address_used = 5 * kGiB;
  EXPECT_EQ(memory_budget(s).bytes, 0u);

  // Memory the heap keeps after frees is reusable under every bound.
  s.heap_free = 2 * kGiB;
  EXPECT_EQ(memory_budget(s).bytes, 2 * kGiB);
}

TEST(Memory, WorkFitsInNinetyPercentOfTheBudget) {
  const auto budget = [](uint64_t bytes) { return MemoryBudget{bytes, "MemAvailable"}; };
  EXPECT_TRUE(fits(0, budget(0)));
  EXPECT_TRUE(fits(9 * kGiB, budget(10 * kGiB)));  // exactly the usable share
  EXPECT_FALSE(fits(9 * kGiB + 1, budget(10 * kGiB)));
  EXPECT_FALSE(fits(1, budget(0)));
  EXPECT_FALSE(fits(30 * kGiB, budget(22 * kGiB)));  // a 1e8 kim-complexity row as extrapolated on a 24 GiB machine
  EXPECT_TRUE(fits(30 * kGiB, MemoryBudget{})) << "no bound read: no limit";
}

TEST(Memory, WorkBeyondTheUsableShareIsRefusedNamingWhatAndWhy) {
  const MemoryBudget budget{10 * kGiB, "the address-space limit of 10.00 GiB (ulimit -v)"};
  EXPECT_NO_THROW(require_memory(9 * kGiB, "a job", "do less", budget)) << "exactly the usable share";
  EXPECT_NO_THROW(require_memory(1 * kGiB, "a job", "do less", MemoryBudget{}));
  try {
    require_memory(9 * kGiB + 1024 * 1024, "render plain-rt at 8000x8000", "lower the resolution", budget);
    FAIL() << "not refused";
  } catch (const ResourceError& e) {
    EXPECT_EQ(e.code(), ExitCode::environment);
    const std::string m = e.what();
    EXPECT_EQ(m,
              "render plain-rt at 8000x8000 needs about 9.00 GiB of memory, but only 9.00 GiB may be used: 90 % of "
              "the 10.00 GiB left by the address-space limit of 10.00 GiB (ulimit -v); lower the resolution");
  }
  EXPECT_THROW(require_memory(1, "a job", "do less", MemoryBudget{0, "MemAvailable"}), ResourceError);
}

TEST(Memory, ThisProcessHasABudget) {
  // Linux always reports MemAvailable; the budget is then finite and names its bound.
  const MemorySources s = read_memory_sources();
  ASSERT_TRUE(s.mem_available.has_value());
  const MemoryBudget b = memory_budget(s);
  EXPECT_LT(b.bytes, UINT64_MAX);
  EXPECT_FALSE(b.bound.empty());
  EXPECT_GT(resident_bytes(), 0u);
  EXPECT_GE(peak_resident_bytes(), resident_bytes());
}

}  // namespace
}  // namespace sb
