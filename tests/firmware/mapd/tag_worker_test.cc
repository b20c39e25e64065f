#include "firmware/mapd/tag_worker.h"

#include <gtest/gtest.h>

#include <chrono>
#include <stdexcept>
#include <thread>

#include "tests/mapping/tags/synthetic_tag_image.h"

namespace rover::mapd {
namespace {

using mapping::testing::RenderTag;
using mapping::testing::TagAt;
using mapping::testing::TestCamera;

mapping::TagObserverOptions OnePost() {
  mapping::TagObserverOptions o;
  o.model.kind = mapping::TagErrorModelKind::kAnalytic;  // no table to build
  mapping::TagMarker post;
  post.id = 3;
  post.size_m = 0.16;
  post.landmark = 5;
  o.markers = {post};
  return o;
}

TEST(TagWorkerTest, ObservesSubmittedImagesAndKeepsTheirSighting) {
  TagWorker worker(OnePost(), TestCamera(), cv::Size(752, 480),
                   std::vector<mapping::TagErrorTable>{}, 5);
  TagSighting sighting;
  sighting.stamp_ns = 42;
  sighting.frame_id = 2;
  sighting.T_local_body.translation() = Eigen::Vector3d(1, 2, 0);
  worker.Submit(RenderTag(3, 0.16, TagAt(1.5, 0.5, 0.1), TestCamera()), sighting);
  worker.Flush();
  const std::vector<TagResult> results = worker.TakeResults();
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].sighting.stamp_ns, 42);
  EXPECT_EQ(results[0].sighting.frame_id, 2u);
  EXPECT_TRUE(results[0].sighting.T_local_body.isApprox(sighting.T_local_body));
  ASSERT_EQ(results[0].observations.size(), 1u);
  EXPECT_TRUE(results[0].observations[0].accepted) << results[0].observations[0].refusal;
  EXPECT_EQ(results[0].observations[0].marker->landmark, 5);
  EXPECT_TRUE(worker.TakeResults().empty()) << "taken once";
}

TEST(TagWorkerTest, AnImageOfTheWrongSizeIsCountedAndTheNextOneStillWorks) {
  TagWorker worker(OnePost(), TestCamera(), cv::Size(752, 480),
                   std::vector<mapping::TagErrorTable>{}, 5);
  worker.Submit(cv::Mat(100, 100, CV_8UC1, cv::Scalar(0)), TagSighting{});
  worker.Flush();
  worker.Submit(RenderTag(3, 0.16, TagAt(1.2, 0.4), TestCamera()), TagSighting{});
  worker.Flush();
  const TagWorkerStats stats = worker.Stats();
  EXPECT_EQ(stats.failed, 1u);
  EXPECT_EQ(stats.processed, 1u);
  EXPECT_EQ(stats.submitted, stats.processed + stats.failed + stats.dropped);
  EXPECT_EQ(stats.observer.accepted, 1u);
  EXPECT_EQ(worker.TakeResults().size(), 1u);
}

TEST(TagWorkerTest, ABlankImageGivesNoResult) {
  TagWorker worker(OnePost(), TestCamera(), cv::Size(752, 480),
                   std::vector<mapping::TagErrorTable>{}, 5);
  worker.Submit(cv::Mat(480, 752, CV_8UC1, cv::Scalar(90)), TagSighting{});
  worker.Flush();
  EXPECT_TRUE(worker.TakeResults().empty());
  EXPECT_EQ(worker.Stats().processed, 1u);
}

TEST(TagWorkerTest, TablesFailingToLoadSwitchDetectionOffWithTheReason) {
  mapping::TagObserverOptions options = OnePost();
  options.model.kind = mapping::TagErrorModelKind::kTable;
  TagWorker worker(options, TestCamera(), cv::Size(752, 480),
                   TagTableLoader([]() -> std::vector<mapping::TagErrorTable> {
                     throw std::runtime_error("no table in /nowhere");
                   }),
                   5);
  worker.Flush();  // returns once the set-up has failed
  std::optional<std::string> error;
  for (int k = 0; k < 200 && !error; ++k) {
    error = worker.TakeError();
    if (!error) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(error.has_value());
  EXPECT_NE(error->find("no table in /nowhere"), std::string::npos) << *error;
  EXPECT_FALSE(worker.TakeError().has_value()) << "said once";
  worker.Submit(RenderTag(3, 0.16, TagAt(1.5, 0.5), TestCamera()), TagSighting{});
  worker.Flush();
  EXPECT_TRUE(worker.TakeResults().empty());
  EXPECT_EQ(worker.Stats().not_ready, 1u);
  EXPECT_EQ(worker.Stats().processed, 0u);
}

TEST(TagWorkerTest, ImagesHandedOverWhileTheTablesLoadAreObservedAfterwards) {
  TagWorker worker(OnePost(), TestCamera(), cv::Size(752, 480), TagTableLoader([] {
                     std::this_thread::sleep_for(std::chrono::milliseconds(100));
                     return std::vector<mapping::TagErrorTable>{};
                   }),
                   5);
  worker.Submit(RenderTag(3, 0.16, TagAt(1.5, 0.5), TestCamera()), TagSighting{});
  worker.Flush();
  EXPECT_EQ(worker.TakeResults().size(), 1u);
  EXPECT_EQ(worker.Stats().not_ready, 0u);
}

}  // namespace
}  // namespace rover::mapd
