// The session API under mpirun -np 2 and -np 3 (ctest runs this suite on every rank).
#include <gtest/gtest.h>

#include "core/errors.h"
#include "mpi/rank_stats.h"
#include "mpi/session.h"

namespace raysift::mpi {
namespace {

TEST(MpiSession, RunsUnderMpirunWithSeveralRanks) {
  ASSERT_TRUE(built_with_mpi());
  EXPECT_GE(size(), 2);  // ctest starts this suite with -np 2 or 3
  EXPECT_GE(rank(), 0);
  EXPECT_LT(rank(), size());
  EXPECT_EQ(sum_all(1.0), double(size()));
  EXPECT_EQ(max_all(rank()), double(size() - 1));
  EXPECT_EQ(min_all(rank()), 0.0);
}

TEST(MpiSession, BroadcastSendsTheRootsBytesAndJsonToEveryRank) {
  const int root = size() - 1;
  std::vector<std::uint8_t> bytes;
  if (rank() == root) bytes = {1, 2, 3, 250};
  broadcast(bytes, root);
  EXPECT_EQ(bytes, (std::vector<std::uint8_t>{1, 2, 3, 250}));
  const Json j = broadcast_json(Json{{"from", rank()}, {"x", 0.1}});
  EXPECT_EQ(j["from"], 0);
  EXPECT_EQ(j["x"].get<double>(), 0.1);  // JSON text keeps doubles exactly (shortest round-trip form)
}

TEST(MpiSession, GatherCollectsEveryRankInRankOrderOnTheRootOnly) {
  const Json all = gather_json(Json{{"rank", rank()}, {"squares", rank() * rank()}});
  if (!is_root()) {
    EXPECT_TRUE(all.empty());
    return;
  }
  ASSERT_EQ(all.size(), std::size_t(size()));
  for (int r = 0; r < size(); ++r) EXPECT_EQ(all[r]["squares"], r * r);
}

TEST(MpiSession, ExchangeSwapsBuffersWithThePeerAndCountsTheBytes) {
  if (rank() >= size() / 2 * 2) return;  // an odd last rank has no partner
  const int peer = rank() ^ 1;
  const Traffic before = traffic();
  std::vector<float> out(1000, float(rank()) + 0.5f), in(1000, -1.0f);
  exchange(peer, out, in);
  for (float v : in) ASSERT_EQ(v, float(peer) + 0.5f);
  EXPECT_EQ(traffic().sent - before.sent, 4000u);
  EXPECT_EQ(traffic().received - before.received, 4000u);
}

TEST(MpiSession, AllOrNoneThrowsTheSameFailureOnEveryRank) {
  EXPECT_NO_THROW(all_or_none([] {}));
  try {
    all_or_none([] {
      if (rank() == 1) throw IoError("brick.vdb: truncated");
    });
    FAIL() << "rank " << rank() << " did not throw";
  } catch (const RankFailure& e) {
    EXPECT_STREQ(e.what(), "rank 1: brick.vdb: truncated");
    EXPECT_EQ(e.exit_code, 1);
  }
  try {  // the lowest failing rank wins; a usage error keeps exit code 2
    all_or_none([] {
      if (rank() >= 1) throw UsageError("bad flag on rank " + std::to_string(rank()));
    });
    FAIL();
  } catch (const RankFailure& e) {
    EXPECT_STREQ(e.what(), "rank 1: bad flag on rank 1");
    EXPECT_EQ(e.exit_code, 2);
  }
}

TEST(MpiSession, NestedAgreementKeepsTheInnerRankName) {
  try {
    all_or_none([] { all_or_none([] { if (rank() == size() - 1) throw IoError("late"); }); });
    FAIL();
  } catch (const RankFailure& e) {
    EXPECT_EQ(std::string(e.what()), "rank " + std::to_string(size() - 1) + ": late");
  }
}

TEST(MpiRankStats, RootGetsOneRowPerRankAndTheSums) {
  RankStats mine;
  mine.active_voxels_loaded = std::uint64_t(10 + rank());
  mine.render_ms = 1.5;
  const Json j = gather_rank_stats(mine, "data");
  if (!is_root()) {
    EXPECT_TRUE(j.empty());
    return;
  }
  EXPECT_EQ(j["distribute"], "data");
  ASSERT_EQ(j["ranks"].size(), std::size_t(size()));
  std::uint64_t expected = 0;
  for (int r = 0; r < size(); ++r) {
    EXPECT_EQ(j["ranks"][r]["rank"], r);
    expected += std::uint64_t(10 + r);
  }
  EXPECT_EQ(j["ranks_total"]["active_voxels_loaded"], expected);
  EXPECT_EQ(j["ranks_total"]["render_ms"].get<double>(), 1.5 * size());
}

}  // namespace
}  // namespace raysift::mpi
