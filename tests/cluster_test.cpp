// The logic of a render over MPI ranks that needs no MPI: how samples and a host's
// devices are shared out, how failures are said, what a cluster of one does, and how
// a launch by an MPI launcher is recognised. The ranks themselves run under mpirun in
// tests/command/mpi_command_test.cpp.
#include <gtest/gtest.h>

#include <cstdlib>
#include <random>

#include "app/cluster.hpp"
#include "app/cluster_launch.hpp"
#include "app/distributed.hpp"

namespace wt::app {
namespace {

TEST(RankSamples, TileTheRangeInRankOrderInProportionToTheWeights) {
  const auto ranges = rank_samples(0, 12, {1, 1, 1});
  ASSERT_EQ(ranges.size(), 3u);
  for (int r = 0; r < 3; ++r) {
    EXPECT_EQ(ranges[r].first, 4 * r);
    EXPECT_EQ(ranges[r].count, 4);
  }
  const auto weighted = rank_samples(100, 300, {2, 1});  // a host with two GPUs, one with one
  EXPECT_EQ(weighted[0].first, 100);
  EXPECT_EQ(weighted[0].count, 200);
  EXPECT_EQ(weighted[1].first, 300);
  EXPECT_EQ(weighted[1].count, 100);

  std::mt19937 rng(7);
  for (int trial = 0; trial < 500; ++trial) {
    const int32_t first = static_cast<int32_t>(rng() % 50), count = static_cast<int32_t>(1 + rng() % 200);
    std::vector<double> weights(1 + rng() % 9);
    for (double& w : weights) w = 1 + rng() % 8;
    const auto got = rank_samples(first, count, weights);
    ASSERT_EQ(got.size(), weights.size());
    int32_t at = first;
    for (const SamplePass& p : got) {
      ASSERT_EQ(p.first, at);  // contiguous, in rank order
      ASSERT_GE(p.count, 0);
      at += p.count;
    }
    ASSERT_EQ(at, first + count);  // every sample once
  }
}

TEST(LocalShare, TheRanksOfAHostShareItsDevicesOut) {
  EXPECT_EQ(local_share({0, 1}, 0, 1), (std::vector<int>{0, 1}));
  EXPECT_EQ(local_share({0, 1}, 0, 2), (std::vector<int>{0}));
  EXPECT_EQ(local_share({0, 1}, 1, 2), (std::vector<int>{1}));
  EXPECT_EQ(local_share({0, 1, 2, 3}, 1, 2), (std::vector<int>{1, 3}));
  EXPECT_EQ(local_share({4, 5, 6}, 2, 3), (std::vector<int>{6}));
  EXPECT_EQ(local_share({0}, 1, 2), (std::vector<int>{0}));  // more ranks than devices: they share
  EXPECT_EQ(local_share({0, 1}, 2, 3), (std::vector<int>{0}));
  EXPECT_TRUE(local_share({}, 1, 2).empty());  // the CPU backend: no devices to share
}

TEST(DescribeFailures, RanksFailingAlikeShareOneClause) {
  EXPECT_EQ(describe_failures({{2, "node3", 2, "s.json: cannot open scene file"}}, 3),
            "rank 2 of 3 (node3): s.json: cannot open scene file");
  EXPECT_EQ(describe_failures({{0, "a", 1, "CUDA error: x"}, {1, "a", 2, "bad"}, {3, "b", 1, "CUDA error: x"}}, 4),
            "ranks 0, 3 of 4 (a, b): CUDA error: x; rank 1 of 4 (a): bad");
  // Hosts are named whole: one whose name holds another's is still named.
  EXPECT_EQ(describe_failures({{0, "node12", 1, "x"}, {1, "node1", 1, "x"}}, 2), "ranks 0, 1 of 2 (node12, node1): x");
}

TEST(Cluster, OfOneProcessExchangesWithItselfAlone) {
  const Cluster one;
  EXPECT_FALSE(one.distributed());
  EXPECT_TRUE(one.root());
  EXPECT_EQ(one.gather("x"), (std::vector<std::string>{"x"}));
  EXPECT_EQ(one.broadcast("y"), "y");
  std::vector<float> film = {1, 2, 3};
  one.sum_to_root(film);
  EXPECT_EQ(film, (std::vector<float>{1, 2, 3}));
  EXPECT_THROW(one.send(1, 0, "z"), std::logic_error);
}

// Sets an environment variable for one scope.
struct ScopedVariable {
  ScopedVariable(const char* name, const char* value) : name(name) { setenv(name, value, 1); }
  ~ScopedVariable() { unsetenv(name); }
  const char* name;
};

TEST(Cluster, ALaunchIsRecognisedFromTheLaunchersVariables) {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "SLURM_STEP_NUM_TASKS", "PMIX_RANK",
                           kSingleProcessVariable}) {
    ASSERT_EQ(std::getenv(name), nullptr) << name << " is set: this test must run outside an MPI launch";
  }
  EXPECT_EQ(launched_ranks(), 1);
  {
    ScopedVariable size("OMPI_COMM_WORLD_SIZE", "3");
    EXPECT_EQ(launched_ranks(), 3);
    ScopedVariable single(kSingleProcessVariable, "1");  // a batch's job process
    EXPECT_EQ(launched_ranks(), 1);
  }
  {
    ScopedVariable size("SLURM_STEP_NUM_TASKS", "8");
    EXPECT_EQ(launched_ranks(), 8);
  }
  {
    ScopedVariable rank("PMIX_RANK", "0");  // launched, how many ranks unsaid
    EXPECT_EQ(launched_ranks(), 0);
  }
  if (!built_with_mpi()) {
    // Launched as one of several by a build that cannot be one: refused, saying why.
    ScopedVariable size("OMPI_COMM_WORLD_SIZE", "4");
    try {
      start_cluster(nullptr, nullptr);
      FAIL() << "a build without MPI started as one of 4 ranks";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("built without MPI"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("one of 4 MPI ranks"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace wt::app
