#include "mapping/tags/tag_observer.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "core/config/config.h"
#include "core/log/msgs/message_traits.h"
#include "mapping/tags/tag_image_renderer.h"
#include "mapping/tags/tag_pattern.h"
#include "tests/mapping/tags/synthetic_tag_image.h"
#include "tests/support/temp_dir.h"

namespace rover::mapping {
namespace {

using testing::RenderTag;
using testing::TagAt;
using testing::TestCamera;

const cv::Size kImage(752, 480);

TagErrorTable SmallTable(double size_m) {
  TagErrorTableSpec spec;
  spec.camera = TestCamera();
  spec.tag_size_m = size_m;
  spec.distance_steps = 8;
  spec.tilt_steps = 9;
  return TagErrorTable::Build(spec);
}

const std::vector<TagErrorTable>& Tables() {
  static const std::vector<TagErrorTable> tables{SmallTable(0.16), SmallTable(0.24)};
  return tables;
}

TagObserverOptions TwoMarkers() {
  TagObserverOptions o;
  o.model.kind = TagErrorModelKind::kTable;  // the tables' checks and loading
  TagMarker post;
  post.id = 3;
  post.size_m = 0.16;
  post.landmark = 12;
  TagMarker rover;
  rover.id = 7;
  rover.size_m = 0.24;
  rover.carrier = TagMarker::Carrier::kRobot;
  rover.robot = 1;
  o.markers = {post, rover};
  return o;
}

TEST(TagObserverTest, AcceptsAConfiguredTagWithItsPoseAndCovariance) {
  TagObserver observer(TwoMarkers(), TestCamera(), kImage, Tables());
  for (const auto& [id, size_m] : {std::pair{3, 0.16}, std::pair{7, 0.24}}) {
    const Eigen::Isometry3d T = TagAt(1.8, 0.5, -0.2);
    const auto seen = observer.Observe(RenderTag(id, size_m, T, TestCamera()));
    ASSERT_EQ(seen.size(), 1u);
    const TagObservation& o = seen[0];
    ASSERT_TRUE(o.accepted) << o.refusal;
    ASSERT_NE(o.marker, nullptr);
    EXPECT_EQ(o.marker->id, id);
    EXPECT_LT((o.pose->best.T_camera_tag.translation() - T.translation()).norm(), 0.02);
    EXPECT_GT(o.uncertainty.covariance.ldlt().vectorD().minCoeff(), 0.0);
    // The log record carries what a replay needs, through CDR and back.
    const auto bytes = log::SerializeMessage(ToMsg(o, 1'500'000'000, "cam0"));
    log::rover_msgs::TagDetection m;
    ASSERT_TRUE(log::DeserializeMessage(std::span(bytes.data(), bytes.size()), &m));
    EXPECT_EQ(m.id, id);
    EXPECT_TRUE(m.accepted);
    EXPECT_EQ(std::string(m.header.frame_id.view()), "cam0");
    EXPECT_EQ(m.header.stamp.sec, 1);
    EXPECT_DOUBLE_EQ(m.corners_px[5], o.detection.corners_px[2].y());
    EXPECT_DOUBLE_EQ(m.covariance[14], o.uncertainty.covariance(2, 2));
    EXPECT_NEAR(m.pose.position.z, o.pose->best.T_camera_tag.translation().z(), 1e-12);
  }
  EXPECT_EQ(observer.stats().accepted, 2u);
  EXPECT_EQ(observer.stats().images, 2u);
  EXPECT_EQ(TwoMarkers().markers[1].carrier, TagMarker::Carrier::kRobot);
}

TEST(TagObserverTest, AnIdNotConfiguredIsRefusedAndCounted) {
  TagObserver observer(TwoMarkers(), TestCamera(), kImage, Tables());
  const auto seen = observer.Observe(RenderTag(9, 0.16, TagAt(1.5, 0.4), TestCamera()));
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_FALSE(seen[0].accepted);
  EXPECT_EQ(seen[0].refusal, "tag id 9 is not in the configuration");
  EXPECT_TRUE(seen[0].not_configured);
  EXPECT_EQ(observer.stats().not_configured, 1u);
  EXPECT_EQ(observer.stats().accepted, 0u);
}

TEST(TagObserverTest, TablesMustFitTheCameraAndEveryMarkerSize) {
  calib::RectifiedIntrinsics other = TestCamera();
  other.fx += 20.0;
  try {
    TagObserver observer(TwoMarkers(), other, kImage, Tables());
    FAIL() << "tables for another camera were accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("another camera"), std::string::npos) << e.what();
  }
  try {
    TagObserver observer(TwoMarkers(), TestCamera(), kImage, {Tables()[0]});
    FAIL() << "a marker size without a table was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no tag error table for tag36h11 240 mm"),
              std::string::npos)
        << e.what();
  }
  TagObserverOptions analytic = TwoMarkers();
  analytic.model.kind = TagErrorModelKind::kAnalytic;
  EXPECT_NO_THROW(TagObserver(analytic, TestCamera(), kImage, {}));
  TagObserver observer(TwoMarkers(), TestCamera(), kImage, Tables());
  EXPECT_THROW(observer.Observe(cv::Mat(240, 376, CV_8UC1, cv::Scalar(0))), std::invalid_argument);
}

TEST(TagObserverTest, LoadsItsConfigurationAndNamesWhatIsWrong) {
  const TagObserverOptions o = TagObserverOptions::Load(ConfigNode::LoadString(
      "families: [tag36h11]\nquad_decimate: 1\nmax_border_offset_px: 0.6\nmodel: "
      "analytic\ncorner_sigma_px: 0.05\n"
      "aligned_edge_sigma_px: 0.1\nmax_tilt_deg: 70\nmarkers:\n"
      "  - {id: 3, size_m: 0.16, landmark: 12}\n  - {id: 7, size_m: 0.24, robot: 1}\n",
      "tags.yaml"));
  ASSERT_EQ(o.markers.size(), 2u);
  EXPECT_EQ(o.markers[0].landmark, 12);
  EXPECT_EQ(o.markers[1].carrier, TagMarker::Carrier::kRobot);
  EXPECT_EQ(o.model.kind, TagErrorModelKind::kAnalytic);
  EXPECT_DOUBLE_EQ(o.model.corner_sigma_px, 0.05);
  EXPECT_DOUBLE_EQ(o.model.aligned_edge_sigma_px, 0.1);
  EXPECT_DOUBLE_EQ(o.model.max_tilt_deg, 70.0);
  EXPECT_DOUBLE_EQ(o.detector.quad_decimate, 1.0);
  EXPECT_DOUBLE_EQ(o.detector.max_border_offset_px, 0.6);
  try {
    TagObserverOptions::Load(
        ConfigNode::LoadString("markers:\n  - {id: 3, size_m: 0.16, landmark: 1}\n  - {id: 3, "
                               "size_m: 0.16, landmark: 2}\n",
                               "tags.yaml"));
    FAIL() << "a duplicate id was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("configured twice"), std::string::npos) << e.what();
  }
  EXPECT_THROW(TagObserverOptions::Load(ConfigNode::LoadString(
                   "markers:\n  - {id: 600, size_m: 0.16, landmark: 1}\n", "tags.yaml")),
               ConfigError);
}

TEST(TagObserverTest, AnAmbiguousDetectionComesWithBothSolutionsCovariancesAndTheInflatedOne) {
  TagObserver observer(TwoMarkers(), TestCamera(), kImage, Tables());
  int ambiguous = 0;
  // Small, far and nearly head-on: the planar ambiguity at its worst.
  for (double d = 3.0; d <= 6.0; d += 0.25) {
    for (const TagObservation& o :
         observer.Observe(RenderTag(3, 0.16, TagAt(d, 0.1, 0.05), TestCamera()))) {
      if (!o.uncertainty.ambiguous) continue;
      ++ambiguous;
      EXPECT_FALSE(o.accepted);
      ASSERT_TRUE(o.pose.has_value());
      EXPECT_TRUE(o.solutions[0].accepted);
      EXPECT_TRUE(o.solutions[1].accepted);
      EXPECT_TRUE(o.inflated.accepted);
      EXPECT_GE(o.inflated.covariance.trace(), o.solutions[0].covariance.trace());
      // The detection's perturbation goes with whichever is logged.
      for (const TagUncertainty* u : {&o.solutions[0], &o.solutions[1], &o.inflated}) {
        EXPECT_EQ(u->perturbation.flipped, o.uncertainty.perturbation.flipped);
        EXPECT_EQ(u->perturbation.solved, o.uncertainty.perturbation.solved);
      }
    }
  }
  EXPECT_GT(ambiguous, 0) << "no ambiguous detection to check";
}

TEST(LoadTagErrorTablesTest, ReadsTheTableOfEachSizeFromTheFolder) {
  const rover::testing::TempDir dir("tag_tables");
  const std::string folder = dir.path().string();
  for (const TagErrorTable& t : Tables()) {
    t.Save(folder + "/" + TagErrorTableFileName("tag36h11", t.spec().tag_size_m));
  }
  std::vector<std::string> said;
  const std::vector<TagErrorTable> tables =
      LoadTagErrorTables(TwoMarkers(), TestCamera(), kImage, folder, false,
                         [&](const std::string& line) { said.push_back(line); });
  ASSERT_EQ(tables.size(), 2u);
  EXPECT_DOUBLE_EQ(tables[0].spec().tag_size_m, 0.16);
  EXPECT_DOUBLE_EQ(tables[1].spec().tag_size_m, 0.24);
  EXPECT_EQ(said.size(), 2u);
  // The analytic model needs none.
  TagObserverOptions analytic = TwoMarkers();
  analytic.model.kind = TagErrorModelKind::kAnalytic;
  EXPECT_TRUE(LoadTagErrorTables(analytic, TestCamera(), kImage, folder, false).empty());
}

TEST(LoadTagErrorTablesTest, AMissingOrForeignTableIsRefusedWithTheCommandThatMakesIt) {
  const rover::testing::TempDir dir("tag_tables");
  const std::string folder = dir.path().string();
  try {
    LoadTagErrorTables(TwoMarkers(), TestCamera(), kImage, folder, false);
    FAIL() << "no table, no build, yet no error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("tag_errors_tag36h11_160mm.yaml"), std::string::npos) << what;
    EXPECT_NE(what.find("rover-tags lut"), std::string::npos) << what;
    EXPECT_NE(what.find("--tag-size-m 0.16"), std::string::npos) << what;
  }
  // Tables for another camera (another focal length) are refused as well.
  calib::RectifiedIntrinsics other = TestCamera();
  other.fx += 20.0;
  other.fy += 20.0;
  for (const TagErrorTable& t : Tables()) {
    t.Save(folder + "/" + TagErrorTableFileName("tag36h11", t.spec().tag_size_m));
  }
  try {
    LoadTagErrorTables(TwoMarkers(), other, kImage, folder, false);
    FAIL() << "a table for another camera was taken";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("another camera"), std::string::npos) << e.what();
  }
}

TEST(LoadTagErrorTablesTest, BuildsAndKeepsAMissingTableWhenAskedTo) {
  const rover::testing::TempDir dir("tag_tables");
  const std::string folder = dir.path().string() + "/tables";
  TagObserverOptions one = TwoMarkers();
  one.markers.resize(1);  // one size: one table to build
  TagErrorTableSpec grid;
  grid.distance_steps = 8;
  grid.tilt_steps = 9;
  const std::vector<TagErrorTable> built =
      LoadTagErrorTables(one, TestCamera(), kImage, folder, true, {}, grid);
  EXPECT_EQ(built.at(0).spec().distance_steps, 8);
  ASSERT_EQ(built.size(), 1u);
  EXPECT_GT(built[0].detected_cells(), 0u);
  // The second time it is read, not built: the same cells.
  const std::vector<TagErrorTable> read =
      LoadTagErrorTables(one, TestCamera(), kImage, folder, false);
  ASSERT_EQ(read.size(), 1u);
  EXPECT_NEAR(read[0].Lookup(2.0, 0.3)(0), built[0].Lookup(2.0, 0.3)(0), 1e-9);
  EXPECT_NO_THROW(TagObserver(one, TestCamera(), kImage, read));
}

}  // namespace
}  // namespace rover::mapping
