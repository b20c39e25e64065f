// The two-rovers scenario: both rovers carry tags and record, so each sees
// the other (mutual sightings), and each has its own dataset.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "hil/sim/dataset/dataset_generator.h"
#include "hil/sim/motion/rover_trajectory.h"
#include "hil/sim/render/stereo_renderer.h"
#include "tests/hil/sim/render/tag_detection.h"
#include "tests/support/temp_dir.h"

namespace rover::sim {
namespace {

namespace fs = std::filesystem;

Scenario TwoRovers() {
  return LoadScenario(FindScenario(DefaultScenarioDir(), "two-rovers"), DefaultSimConfigDir());
}

// Tag ids on `carrier_name`'s body.
std::vector<int> TagIdsOf(const World& world, const std::string& carrier_name) {
  std::vector<int> ids;
  for (const TagCarrier& c : world.carriers) {
    if (c.name != carrier_name) continue;
    for (const TagMarker& t : c.tags) ids.push_back(t.id);
  }
  return ids;
}

bool SeesAnyOf(const cv::Mat& image, const std::vector<int>& ids) {
  for (const Detection& d : DetectTags(image)) {
    if (std::find(ids.begin(), ids.end(), d.id) != ids.end()) return true;
  }
  return false;
}

// Bearing of `target` in the camera of `viewer` (0 = straight ahead).
double Bearing(const TrajectorySample& viewer, const TrajectorySample& target) {
  const Eigen::Vector3d d =
      viewer.q_world_body.conjugate() * (target.p_world_body - viewer.p_world_body);
  return std::atan2(d.y(), d.x());
}

TEST(TwoRoversTest, EachRoverSeesTheOthersTags) {
  const Scenario s = TwoRovers();
  const World world = World::Generate(s.world, 1);
  ASSERT_EQ(TagIdsOf(world, "rover_a").size(), 5u);
  ASSERT_EQ(TagIdsOf(world, "rover_b").size(), 5u);
  const RoverTrajectory a(s.route, world.terrain);
  const RoverTrajectory b(s.other_rover_routes[0], world.terrain);
  // The moment the routes bring them closest while face to face.
  double t_meet = -1, closest_m = 7.0;
  for (double t = 0; t < a.duration_s(); t += 0.25) {
    const TrajectorySample sa = a.Evaluate(t), sb = b.Evaluate(t);
    const double d = (sa.p_world_body - sb.p_world_body).norm();
    if (d < closest_m && d > 2.0 && std::abs(Bearing(sa, sb)) < 0.35 &&
        std::abs(Bearing(sb, sa)) < 0.35) {
      t_meet = t;
      closest_m = d;
    }
  }
  ASSERT_GE(t_meet, 0.0) << "the routes never bring the rovers face to face";

  StereoRenderer renderer(world, s.camera);
  const std::vector<const RoverTrajectory*> carriers = {&b, &a};  // world order: rover_b, rover_a
  std::vector<Eigen::Isometry3d> poses;
  RenderedStereoFrame view;
  MovingCarrierPoses(carriers, 1, t_meet, &poses);  // a's own body hidden
  renderer.Render(PoseOf(a.Evaluate(t_meet)), poses, 0, &view);
  EXPECT_TRUE(SeesAnyOf(view.cam0, TagIdsOf(world, "rover_b")))
      << "t = " << t_meet << ", " << closest_m << " m apart";
  MovingCarrierPoses(carriers, 0, t_meet, &poses);  // b's own body hidden
  renderer.Render(PoseOf(b.Evaluate(t_meet)), poses, 0, &view);
  EXPECT_TRUE(SeesAnyOf(view.cam0, TagIdsOf(world, "rover_a")))
      << "t = " << t_meet << ", " << closest_m << " m apart";
}

TEST(TwoRoversTest, EveryRoverGetsItsOwnDataset) {
  const testing::TempDir dir("two_rovers");
  GenerateOptions options;
  options.out_dir = dir.path().string();
  options.max_duration_s = 0.3;
  const GenerateResult r = GenerateDataset(TwoRovers(), options);
  EXPECT_EQ(r.rover_datasets, 2u);
  EXPECT_TRUE(fs::exists(dir.path() / "mav0/cam0/data.csv"));
  EXPECT_TRUE(fs::exists(dir.path() / "rover_b/mav0/cam0/data.csv"));
  const auto read = [](const fs::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  };
  // Each rover's tag ground truth lists the other rover, never itself.
  const std::string tags_a = read(dir.path() / "mav0/tags0/data.csv");
  const std::string tags_b = read(dir.path() / "rover_b/mav0/tags0/data.csv");
  EXPECT_NE(tags_a.find(",rover_b,"), std::string::npos);
  EXPECT_EQ(tags_a.find(",rover_a,"), std::string::npos);
  EXPECT_NE(tags_b.find(",rover_a,"), std::string::npos);
  EXPECT_EQ(tags_b.find(",rover_b,"), std::string::npos);
  // Different rovers, different IMU noise.
  EXPECT_NE(read(dir.path() / "mav0/imu0/data.csv"),
            read(dir.path() / "rover_b/mav0/imu0/data.csv"));
}

}  // namespace
}  // namespace rover::sim
