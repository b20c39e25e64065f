#include "hil/sim/dataset/dataset_generator.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "drivers/replay/euroc_dataset.h"
#include "tests/support/temp_dir.h"

namespace rover::sim {
namespace {

namespace fs = std::filesystem;

std::string ReadAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

Scenario Short() {
  return LoadScenario(FindScenario(DefaultScenarioDir(), "short"), DefaultSimConfigDir());
}

GenerateResult Generate(const std::string& dir, uint64_t seed, double duration_s) {
  GenerateOptions options;
  options.seed = seed;
  options.out_dir = dir;
  options.max_duration_s = duration_s;
  return GenerateDataset(Short(), options);
}

// The whole pipeline, twice: same seed, same bytes in every file.
TEST(DatasetGeneratorTest, SameSeedGivesByteIdenticalDatasets) {
  const testing::TempDir a("gen_a"), b("gen_b");
  Generate(a.path().string(), 7, 0.6);
  Generate(b.path().string(), 7, 0.6);
  std::size_t files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(a.path())) {
    if (!entry.is_regular_file()) continue;
    const fs::path relative = fs::relative(entry.path(), a.path());
    ASSERT_TRUE(fs::exists(b.path() / relative)) << relative;
    EXPECT_TRUE(ReadAll(entry.path()) == ReadAll(b.path() / relative)) << relative << " differs";
    ++files;
  }
  EXPECT_GT(files, 30u);
}

TEST(DatasetGeneratorTest, OurEurocReaderReadsTheDataset) {
  const testing::TempDir dir("gen");
  const GenerateResult r = Generate(dir.path().string(), 3, 1.0);
  const drivers::EurocDataset d = drivers::EurocDataset::Load(dir.path().string());
  EXPECT_EQ(d.imu().size(), r.imu_samples);
  EXPECT_NEAR(static_cast<double>(r.imu_samples), 400.0, 2.0);  // 1 s at 400 Hz
  EXPECT_EQ(d.stereo_frames().size(), r.stereo_frames);
  EXPECT_EQ(r.stereo_frames, 10u);  // 10 Hz triggers
  EXPECT_TRUE(d.issues().empty()) << d.issues().front();
  ASSERT_FALSE(d.ground_truth().empty());
  // The rover holds still at the start: ground truth at rest, gravity up.
  EXPECT_LT(d.ground_truth().front().v_world_body_m_s.norm(), 1e-9);
  const Scenario s = Short();
  EXPECT_EQ(d.cam0().intrinsics[0], s.camera.fx_px);
  EXPECT_EQ(d.cam0().distortion[0], s.camera.k1);
  EXPECT_TRUE(d.cam1().T_body_cam.isApprox(s.camera.T_body_cam1(), 1e-12));
  EXPECT_EQ(d.imu_calibration().gyro_noise_density_rad_s_sqrt_hz, s.imu.gyro.noise_density);
  EXPECT_TRUE(fs::exists(dir.path() / "world/heightfield.bin"));
  EXPECT_TRUE(fs::exists(dir.path() / "world/tags.csv"));
}

TEST(DatasetGeneratorTest, RefusesAnOutputThatHoldsADataset) {
  const testing::TempDir dir("gen");
  fs::create_directories(dir.path() / "mav0");
  EXPECT_THROW(Generate(dir.path().string(), 1, 0.2), drivers::DatasetError);
}

}  // namespace
}  // namespace rover::sim
