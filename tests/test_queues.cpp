// Full queues are detected and the frame is redone with larger ones: no work is ever dropped.
#include <gtest/gtest.h>

#include "test_util.h"

namespace pmr {
namespace {

TEST(Queues, FullMtaQueueGrowsAndGivesTheSameImage) {
  const Scene scene = test::random_scene(400, 11, true);
  const Rig rig = test::small_rig(8, 40, 24);
  const test::Rendered ample = test::render(scene, rig);
  ASSERT_GT(ample.mtas.size(), 100u);
  ASSERT_EQ(ample.times.retries, 0);

  PipelineConfig pc;
  pc.debug_outputs = true;
  Pipeline p(test::runtime(), pc);
  p.set_mta_capacity(7);  // far too small
  p.set_scene(scene);
  p.configure(rig, nullptr);
  const StageTimes t = p.render(rig);
  EXPECT_GE(t.retries, 1);
  EXPECT_EQ(t.mtas, ample.mtas.size());
  std::vector<uint16_t> volume;
  p.read_volume(volume);
  EXPECT_TRUE(volume == ample.volume);
  // the grown queue is kept: the next frame needs no retry
  EXPECT_EQ(p.render(rig).retries, 0);
}

TEST(Queues, EmptyAndTinyScenes) {
  const Rig rig = test::small_rig(5, 16, 8);
  for (int n : {0, 1, 2, 3}) {
    const Scene scene = test::random_scene(n, 3, false);
    const test::Rendered out = test::render(scene, rig);
    size_t covered = 0;
    for (uint32_t c : out.count) covered += c;
    if (n == 0) {
      EXPECT_EQ(covered, 0u);
    }
    for (size_t v = 0; v < out.key.size(); ++v) {
      if (out.key[v] == PMR_NO_KEY) {
        ASSERT_EQ(out.volume[v * 4 + 3], 0) << "empty voxel has zero alpha";
      }
    }
  }
}

}  // namespace
}  // namespace pmr
