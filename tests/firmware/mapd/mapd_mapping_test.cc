// mapd's mapping end to end over the in-process transport: roverd's
// calibration, estimates, switches and analytically rendered stereo pairs
// in; submaps (octree, cloud, obstacle flags) logged, the traversability
// grid logged, the global map exported.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <memory>
#include <span>
#include <string>

#include <octomap/OcTree.h>

#include "core/ipc/in_process_transport.h"
#include "core/log/msgs/diagnostic_msgs.h"
#include "core/log/msgs/message_traits.h"
#include "core/log/msgs/nav_msgs.h"
#include "firmware/mapd/mapd.h"
#include "firmware/roverd/mapd_link.h"
#include "mapping/compose/map_export.h"
#include "mapping/compose/submap_log.h"
#include "mapping/slam/graph_log.h"
#include "mapping/tags/tag_image_renderer.h"
#include "mapping/tags/tag_log.h"
#include "mapping/tags/tag_pattern.h"
#include "tests/firmware/mapd/log_topic.h"
#include "tests/firmware/mapd/stereo_scene.h"

namespace rover::mapd {
namespace {

namespace topics = runtime::topics;

ipc::Topic T(std::string_view name) { return *ipc::Topic::Parse(name); }

// Around a rendered tag: pixels that are not the tag's.
constexpr uint8_t kTagBackgroundDn = 111;

class MapdMappingTest : public ::testing::Test {
 protected:
  MapdMappingTest() : transport_(ipc::InProcessTransport::Options{.max_queue_capacity = 8}) {
    dir_ = std::filesystem::path(::testing::TempDir()) /
           ("mapd_mapping_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    // roverd's side: publishes the calibration (with history) at start.
    calibration_ = transport_.MakePublisher<topics::StereoCalibrationMsg>(
        T(topics::kStereoCalibrationTopic), {.history_capacity = 1});
    EXPECT_TRUE(
        calibration_->Publish(roverd::ToCalibrationMsg(scene_.Camera(0), scene_.Camera(1))));
    poses_ = transport_.MakePublisher<topics::PoseMsg>(T(topics::kPoseTopic));
    switches_ = transport_.MakePublisher<topics::FrameSwitchMsg>(T(topics::kFrameSwitchTopic));
    frames_ = transport_.MakePublisher<topics::StereoFrameMsg>(T(topics::kStereoFrameTopic));
  }

  ~MapdMappingTest() override {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }

  std::unique_ptr<Mapd> MakeMapd(std::optional<mapping::TagObserverOptions> tags = std::nullopt) {
    MapdOptions options;
    options.tags = std::move(tags);
    options.pose_queue = 8;
    options.max_mapping_rate_hz = 0.0;
    options.output_stem = (dir_ / "mapd-test").string();
    options.robot_name = "r1";
    return std::make_unique<Mapd>(options, &transport_);
  }

  /// An estimate at `t_s` in `frame`, body at (x, 0, 0) of that frame.
  void Pose(Mapd* mapd, double t_s, uint32_t frame, double x_m) {
    topics::PoseMsg m;
    m.stamp_ns = Time::FromSeconds(t_s).nanoseconds();
    m.frame_id = frame;
    m.p_local_body_m = {x_m, 0.0, 0.0};
    m.position_sigma_m = 0.01;
    ASSERT_TRUE(poses_->Publish(m));
    mapd->Poll();
  }

  /// A pair captured at `t_s` with the body at world x `world_x_m`.
  void Frame(Mapd* mapd, double t_s, double world_x_m, uint64_t sequence, int width_px = 0,
             const cv::Mat& tag_rect0 = cv::Mat()) {
    auto m = std::make_unique<topics::StereoFrameMsg>();
    m->width_px = static_cast<uint32_t>(width_px > 0 ? width_px : scene_.width_px);
    m->height_px = static_cast<uint32_t>(scene_.height_px);
    m->capture_stamp_ns = Time::FromSeconds(t_s).nanoseconds();
    m->sequence = sequence;
    Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
    T_world_body.translation().x() = world_x_m;
    scene_.Render(0, T_world_body, m->cam0.data());
    scene_.Render(1, T_world_body, m->cam1.data());
    if (!tag_rect0.empty()) {
      // A tag in front of cam0 (the scene's cameras rectify to themselves):
      // its pixels over the scene's.
      cv::Mat cam0(scene_.height_px, scene_.width_px, CV_8UC1, m->cam0.data());
      tag_rect0.copyTo(cam0, tag_rect0 != kTagBackgroundDn);
    }
    ASSERT_TRUE(frames_->Publish(*m));
    mapd->Poll();
  }

  void Switch(Mapd* mapd, double t_s, uint32_t old_frame, double dx_m) {
    topics::FrameSwitchMsg sw;
    sw.old_frame_id = old_frame;
    sw.new_frame_id = old_frame + 1;
    sw.stamp_ns = Time::FromSeconds(t_s).nanoseconds();
    sw.p_old_new_m = {dx_m, 0.0, 0.0};
    ASSERT_TRUE(switches_->Publish(sw));
    mapd->Poll();
  }

  testing::StereoScene scene_;
  ipc::InProcessTransport transport_;
  std::filesystem::path dir_;
  std::unique_ptr<ipc::Publisher<topics::StereoCalibrationMsg>> calibration_;
  std::unique_ptr<ipc::Publisher<topics::PoseMsg>> poses_;
  std::unique_ptr<ipc::Publisher<topics::FrameSwitchMsg>> switches_;
  std::unique_ptr<ipc::Publisher<topics::StereoFrameMsg>> frames_;
};

// Occupied leaves of `tree` within `tol_m` of height z (after placing by T).
double FractionNear(const octomap::OcTree& tree, double z_m, double tol_m) {
  int near = 0;
  int all = 0;
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    ++all;
    if (std::abs(it.getZ() - z_m) <= tol_m) ++near;
  }
  return all > 0 ? static_cast<double>(near) / all : 0.0;
}

TEST_F(MapdMappingTest, MapsPairsIntoSubmapsLogsThemAndExportsTheGlobalMap) {
  auto mapd = MakeMapd();
  // Frame 0: the body stands at world x = 0. Two pairs per frame: an
  // obstacle is flagged once a second image confirms it.
  for (int i = 0; i <= 10; ++i) Pose(mapd.get(), 1.0 + 0.01 * i, 0, 0.0);
  Frame(mapd.get(), 1.05, 0.0, 1);
  for (int i = 11; i <= 20; ++i) Pose(mapd.get(), 1.0 + 0.01 * i, 0, 0.0);
  EXPECT_EQ(mapd->stats().images_mapped, 1u) << "mapped once its estimates arrived";
  Frame(mapd.get(), 1.15, 0.0, 2);
  EXPECT_EQ(mapd->stats().images_mapped, 2u);
  // The switch mapd asked for at start: frame 1 has its origin 0.5 m ahead,
  // so the same body position is x = -0.5 there.
  Switch(mapd.get(), 1.2, 0, 0.5);
  for (int i = 21; i <= 40; ++i) Pose(mapd.get(), 1.0 + 0.01 * i, 1, -0.5);
  Frame(mapd.get(), 1.30, 0.0, 3);
  Frame(mapd.get(), 1.35, 0.0, 4);
  for (int i = 41; i <= 50; ++i) Pose(mapd.get(), 1.0 + 0.01 * i, 1, -0.5);
  EXPECT_EQ(mapd->stats().images_mapped, 4u);
  EXPECT_EQ(mapd->stats().submaps_archived, 1u) << "frame 0's submap ends when frame 1 begins";
  mapd->Shutdown();
  EXPECT_EQ(mapd->stats().submaps_archived, 2u);
  EXPECT_GT(mapd->stats().obstacle_points, 50u) << "the box is a step obstacle";
  // The grid is published for a planner, as the log's OccupancyGrid bytes.
  auto grids = transport_.MakeSubscriber<topics::TraversabilityMsg>(
      T(topics::kTraversabilityTopic), {.queue_capacity = 1, .history_request = 1});
  auto grid_msg = std::make_unique<topics::TraversabilityMsg>();
  ASSERT_TRUE(grids->TryTake(grid_msg.get()));
  log::nav_msgs::OccupancyGrid grid;
  ASSERT_TRUE(log::DeserializeMessage(std::span(grid_msg->cdr.data(), grid_msg->cdr_size), &grid));
  EXPECT_EQ(grid.info.width, 200u);
  EXPECT_FLOAT_EQ(grid.info.resolution, 0.05f);
  const auto occupied =
      std::count_if(grid.data.begin(), grid.data.end(), [](int8_t v) { return v > 65; });
  EXPECT_GT(occupied, 5) << "the box";
  const auto level =
      std::count_if(grid.data.begin(), grid.data.end(), [](int8_t v) { return v >= 0 && v < 30; });
  EXPECT_GT(level, 1000) << "level ground";

  // The log: both submaps, with their octree and cloud, and grids.
  const mapping::SubmapLog log = mapping::ReadSubmapLog(mapd->log_path());
  EXPECT_TRUE(log.problems.empty()) << log.problems.front();
  ASSERT_EQ(log.submaps.size(), 2u);
  EXPECT_EQ(log.submaps[1].info.frame_id, 1u);
  EXPECT_TRUE(log.submaps[1].info.has_origin);
  EXPECT_DOUBLE_EQ(log.submaps[1].info.p_previous_origin_m[0], 0.5);
  EXPECT_EQ(std::string(log.submaps[1].info.header.frame_id.view()), "local/r1/1");
  EXPECT_GT(log.submaps[0].info.octree_bytes, 0u);
  EXPECT_GT(log.submaps[0].info.cloud_bytes, 0u);
  EXPECT_EQ(log.statistics.at("submaps"), "2");
  // After each finished submap, what mapd's memory is made of.
  const auto diagnostics = rover::testing::ReadTopic<log::diagnostic_msgs::DiagnosticArray>(
      mapd->log_path(), "/diagnostics");
  ASSERT_EQ(diagnostics.size(), 2u);
  for (std::size_t k = 0; k < diagnostics.size(); ++k) {
    ASSERT_EQ(diagnostics[k].status.size(), 1u);
    const log::diagnostic_msgs::DiagnosticStatus& memory = diagnostics[k].status[0];
    EXPECT_EQ(memory.name, "mapd: memory");
    std::map<std::string, std::string> values;
    for (const auto& kv : memory.values) values[kv.key] = kv.value;
    EXPECT_EQ(values["submaps_archived"], std::to_string(k + 1));
    EXPECT_GT(std::stoull(values.at("rss_anon_kb")), 1000u);
    EXPECT_LE(std::stoull(values.at("rss_anon_kb")), std::stoull(values.at("rss_kb")));
    EXPECT_TRUE(values.count("heap_in_use_kb") && values.count("heap_free_held_kb"));
  }
  EXPECT_NE(mapd->Summary().find("memory: RSS"), std::string::npos) << mapd->Summary();
  EXPECT_GE(log.traversability_grids, 1u);
  for (const mapping::LoggedSubmap& s : log.submaps) {
    // Ground voxels sit at the plane (10 cm voxels: centres within 0.1 m);
    // the box adds a few above it.
    EXPECT_GT(FractionNear(*s.octree, scene_.ground_z_m, 0.1), 0.8) << s.info.index;
    int obstacles_on_box = 0;
    int obstacles_elsewhere = 0;
    const double box_x_in_frame = s.info.frame_id == 0 ? 0.0 : -0.5;
    for (const mapping::CloudPoint& p : *s.cloud) {
      if (!p.obstacle) continue;
      const double x = static_cast<double>(p.p_submap_m.x()) - box_x_in_frame;
      const bool near_box = x > scene_.box_min_xy.x() - 0.35 && x < scene_.box_max_xy.x() + 0.35 &&
                            std::abs(static_cast<double>(p.p_submap_m.y())) < 0.65;
      (near_box ? obstacles_on_box : obstacles_elsewhere)++;
    }
    EXPECT_GT(obstacles_on_box, 20) << s.info.index;
    EXPECT_LT(obstacles_elsewhere, obstacles_on_box / 5) << s.info.index;
  }

  // The exported global map is in frame 0: frame 1's submap is placed by
  // the switch, so both see the ground at the same height and the box at
  // the same place.
  octomap::OcTree exported(0.1);
  ASSERT_TRUE(exported.readBinary(mapd->log_path().substr(0, mapd->log_path().size() - 5) + ".bt"));
  EXPECT_GT(exported.getNumLeafNodes(), 100u);
  EXPECT_GT(FractionNear(exported, scene_.ground_z_m, 0.1), 0.8);
  const mapping::PointCloud cloud =
      mapping::ReadPly(mapd->log_path().substr(0, mapd->log_path().size() - 5) + ".ply");
  EXPECT_GT(cloud.size(), 1000u);
}

TEST_F(MapdMappingTest, ALandmarkTagSeenInThePairsJoinsTheGraphAndTheLog) {
  mapping::TagObserverOptions tags;
  tags.model.kind = mapping::TagErrorModelKind::kAnalytic;  // no table to build
  tags.detector.quad_decimate = 1.0;                        // a small image
  mapping::TagMarker post;
  post.id = 3;
  post.size_m = 0.16;
  post.landmark = 9;
  tags.markers = {post};
  auto mapd = MakeMapd(tags);
  const std::optional<calib::StereoRectifier> rectifier =
      calib::StereoRectifier::Create(scene_.Camera(0), scene_.Camera(1));
  ASSERT_TRUE(rectifier.has_value());
  mapping::TagRenderOptions render;
  render.background_dn = kTagBackgroundDn;
  render.blur_sigma_px = 0.0;
  // Both tags in one image: the tag thread keeps only the newest image it
  // has not started on, so a second image could replace the first.
  Eigen::Isometry3d T_cam_tag = Eigen::Isometry3d::Identity();
  T_cam_tag.linear() = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T_cam_tag.translation() = Eigen::Vector3d(-0.2, -0.1, 1.0);
  cv::Mat image = mapping::RenderTagImage(mapping::MakeTagPattern("tag36h11", 3), 0.16, T_cam_tag,
                                          rectifier->intrinsics(), rectifier->image_size(), render);
  // An id the marker list does not have: logged, counted, no factor.
  Eigen::Isometry3d T_cam_unknown = T_cam_tag;
  T_cam_unknown.translation().x() = 0.25;
  const cv::Mat unknown =
      mapping::RenderTagImage(mapping::MakeTagPattern("tag36h11", 8), 0.16, T_cam_unknown,
                              rectifier->intrinsics(), rectifier->image_size(), render);
  unknown.copyTo(image, unknown != kTagBackgroundDn);
  for (int i = 0; i <= 10; ++i) Pose(mapd.get(), 1.0 + 0.01 * i, 0, 0.0);
  Frame(mapd.get(), 1.05, 0.0, 1, 0, image);
  for (int i = 11; i <= 20; ++i) Pose(mapd.get(), 1.0 + 0.01 * i, 0, 0.0);
  mapd->Shutdown();
  EXPECT_EQ(mapd->stats().images_mapped, 1u);
  EXPECT_EQ(mapd->stats().tag_factors, 1u) << mapd->Summary();
  EXPECT_EQ(mapd->stats().tag_sightings, 1u);
  EXPECT_EQ(mapd->tag_stats().observer.not_configured, 1u);
  EXPECT_NE(mapd->Summary().find("tags: 1 images searched (0 dropped"), std::string::npos)
      << mapd->Summary();
  // Both observations are in the log, the known one accepted with its pose.
  auto logged = mapping::ReadTagDetections(mapd->log_path()).detections;
  ASSERT_EQ(logged.size(), 2u);
  if (logged[0].id != 3) std::swap(logged[0], logged[1]);
  EXPECT_EQ(logged[0].id, 3);
  EXPECT_TRUE(logged[0].accepted) << logged[0].refusal;
  EXPECT_NEAR(logged[0].pose.position.z, 1.0, 0.02);
  EXPECT_EQ(logged[1].id, 8);
  EXPECT_FALSE(logged[1].accepted);
  // The graph has the sighting's pose (v, in frame 0) and the landmark (o).
  const mapping::GraphLogContents graph = mapping::ReadGraphLogs({mapd->log_path()});
  int v = 0, o = 0;
  for (const mapping::GraphFactorRecord& f : graph.factors) {
    if (f.kind == mapping::FactorKind::kFilterPose) {
      ++v;
      EXPECT_EQ(f.a, mapping::GraphKey::Origin(0, 0));
    }
    if (f.kind == mapping::FactorKind::kLandmarkObservation) {
      ++o;
      EXPECT_EQ(*f.b, mapping::GraphKey::Landmark(9));
      EXPECT_TRUE(f.robust);
    }
  }
  EXPECT_EQ(v, 1);
  EXPECT_EQ(o, 1);
}

TEST_F(MapdMappingTest, APairOfTheWrongSizeIsCountedAndMappingGoesOn) {
  auto mapd = MakeMapd();
  for (int i = 0; i <= 20; ++i) Pose(mapd.get(), 1.0 + 0.01 * i, 0, 0.0);
  Frame(mapd.get(), 1.05, 0.0, 1, scene_.width_px - 8);
  EXPECT_EQ(mapd->stats().images_failed, 1u);
  Frame(mapd.get(), 1.15, 0.0, 2);
  EXPECT_EQ(mapd->stats().images_mapped, 1u);
}

TEST_F(MapdMappingTest, APairWithoutEstimatesAroundItIsNotPlaced) {
  auto mapd = MakeMapd();
  for (int i = 0; i <= 20; ++i) Pose(mapd.get(), 2.0 + 0.01 * i, 0, 0.0);
  Frame(mapd.get(), 1.5, 0.0, 1);  // older than every estimate mapd kept
  EXPECT_EQ(mapd->stats().images_unplaced, 1u);
  EXPECT_EQ(mapd->stats().images_mapped, 0u);
}

}  // namespace
}  // namespace rover::mapd
