// World generation: size, determinism, slopes, rocks, crater, tag carriers, albedo.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <set>
#include <stdexcept>
#include <vector>

#include "core/config/config.h"
#include "hil/sim/world/world.h"
#include "mapping/tags/tag_observer.h"
#include "tests/hil/sim/world/test_worlds.h"

namespace rover::sim {
namespace {

using testing::NearRockOrCrater;
using testing::SmallWorld;
using testing::SmallWorldOptions;

constexpr double kDegPerRad = 57.29577951308232;

struct SlopeStats {
  double max_deg = 0.0;
  double fraction_above_8_deg = 0.0;
};

// Slopes over 0.5 m baselines (central differences of +-0.25 m) at every
// sample away from rocks and craters.
SlopeStats MeasureSlopes(const World& world) {
  const Heightfield& t = world.terrain;
  const int half = static_cast<int>(std::lround(0.25 / t.resolution_m()));
  const double baseline = 2.0 * half * t.resolution_m();
  // Mask of samples near rocks and craters, painted per object (fast).
  std::vector<uint8_t> excluded(t.heights_m().size(), 0);
  const auto paint = [&](const Eigen::Vector2d& center, double radius) {
    const int cx =
        static_cast<int>(std::lround((center.x() - t.origin_xy().x()) / t.resolution_m()));
    const int cy =
        static_cast<int>(std::lround((center.y() - t.origin_xy().y()) / t.resolution_m()));
    const int r = static_cast<int>(std::ceil(radius / t.resolution_m()));
    for (int iy = std::max(0, cy - r); iy <= std::min(t.rows() - 1, cy + r); ++iy) {
      for (int ix = std::max(0, cx - r); ix <= std::min(t.cols() - 1, cx + r); ++ix) {
        excluded[static_cast<std::size_t>(iy) * static_cast<std::size_t>(t.cols()) +
                 static_cast<std::size_t>(ix)] = 1;
      }
    }
  };
  for (const Rock& rock : world.rocks) paint(rock.center_xy, RockOuterRadius(rock) + 0.3);
  for (const Crater& crater : world.craters)
    paint(crater.center_xy, CraterOuterRadius(crater) + 0.3);
  SlopeStats stats;
  std::size_t count = 0;
  std::size_t steep = 0;
  for (int iy = half; iy < t.rows() - half; ++iy) {
    for (int ix = half; ix < t.cols() - half; ++ix) {
      if (excluded[static_cast<std::size_t>(iy) * static_cast<std::size_t>(t.cols()) +
                   static_cast<std::size_t>(ix)] != 0) {
        continue;
      }
      const double gx =
          static_cast<double>(t.HeightAtCell(ix + half, iy) - t.HeightAtCell(ix - half, iy)) /
          baseline;
      const double gy =
          static_cast<double>(t.HeightAtCell(ix, iy + half) - t.HeightAtCell(ix, iy - half)) /
          baseline;
      const double deg = std::atan(std::hypot(gx, gy)) * kDegPerRad;
      stats.max_deg = std::max(stats.max_deg, deg);
      ++count;
      steep += deg > 8.0 ? 1U : 0U;
    }
  }
  stats.fraction_above_8_deg = static_cast<double>(steep) / static_cast<double>(count);
  return stats;
}

// Rock height as seen in the terrain: the top above the mean of a ring just outside the rock
// (the ring's mean cancels the ground's slope).
double MeasuredRockHeight(const World& world, const Rock& rock) {
  const double ring = RockOuterRadius(rock) + 0.1;
  double sum = 0.0;
  const int n = 36;
  for (int k = 0; k < n; ++k) {
    const double a = 6.283185307179586 * k / n;
    sum += world.terrain.HeightAt(rock.center_xy.x() + ring * std::cos(a),
                                  rock.center_xy.y() + ring * std::sin(a));
  }
  return world.terrain.HeightAt(rock.center_xy.x(), rock.center_xy.y()) - sum / n;
}

// Largest drop across the crater scarp, the smallest over 72 radial directions.
double SmallestRimDrop(const World& world, const Crater& crater) {
  double smallest = 1e9;
  for (int k = 0; k < 72; ++k) {
    const double a = 6.283185307179586 * k / 72;
    const Eigen::Vector2d u(std::cos(a), std::sin(a));
    double crest = -1e9;
    for (double d = crater.radius_m - 0.05; d <= crater.radius_m + 0.3; d += 0.01) {
      const Eigen::Vector2d p = crater.center_xy + d * u;
      crest = std::max(crest, world.terrain.HeightAt(p.x(), p.y()));
    }
    const Eigen::Vector2d inside =
        crater.center_xy + (crater.radius_m - crater.scarp_width_m - 0.05) * u;
    smallest = std::min(smallest, crest - world.terrain.HeightAt(inside.x(), inside.y()));
  }
  return smallest;
}

void ExpectRocksValid(const World& world) {
  ASSERT_FALSE(world.rocks.empty());
  for (const Rock& rock : world.rocks) {
    EXPECT_GE(rock.height_m, 0.1);
    EXPECT_LE(rock.height_m, 0.6);
    EXPECT_DOUBLE_EQ(RockBumpHeight(rock, rock.center_xy.x(), rock.center_xy.y()), rock.height_m);
    const double measured = MeasuredRockHeight(world, rock);
    EXPECT_GT(measured, 0.1 - 0.03) << "rock at " << rock.center_xy.transpose();
    EXPECT_LT(measured, 0.6 + 0.03) << "rock at " << rock.center_xy.transpose();
  }
}

TEST(WorldTest, DefaultWorldMeetsTheSpecification) {
  const auto start = std::chrono::steady_clock::now();
  const World world = World::Generate(WorldOptions{}, 2024);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("default world (%d x %d heights, %d x %d albedo, %zu rocks) generated in %.2f s\n",
              world.terrain.cols(), world.terrain.rows(), world.albedo.cols, world.albedo.rows,
              world.rocks.size(), seconds);

  const Heightfield& t = world.terrain;
  EXPECT_LE(t.resolution_m(), 0.05);
  EXPECT_GE((t.max_xy() - t.origin_xy()).minCoeff(), 120.0);
  EXPECT_TRUE(t.Contains(-60.0, -60.0));
  EXPECT_TRUE(t.Contains(60.0, 60.0));
  EXPECT_LE(world.albedo.resolution_m, 0.025);
  EXPECT_GE(world.albedo.resolution_m * (world.albedo.cols - 1), 120.0);

  const SlopeStats slopes = MeasureSlopes(world);
  std::printf("max slope %.2f deg, %.1f %% of the ground steeper than 8 deg\n", slopes.max_deg,
              100.0 * slopes.fraction_above_8_deg);
  EXPECT_LE(slopes.max_deg, 20.0 + 0.25);
  EXPECT_GE(slopes.max_deg, 8.0);

  EXPECT_EQ(world.rocks.size(), 400U);
  ExpectRocksValid(world);
  ASSERT_EQ(world.craters.size(), 1U);
  const Crater& crater = world.craters[0];
  EXPECT_GE(crater.center_xy.norm(), 15.0);
  EXPECT_LE(crater.center_xy.norm(), 30.0);
  EXPECT_GT(SmallestRimDrop(world, crater), 0.3);
  for (const Rock& rock : world.rocks) {
    EXPECT_GT(rock.center_xy.norm() - RockOuterRadius(rock), 3.0);
  }
  EXPECT_EQ(world.carriers.size(), 6U);
}

TEST(WorldTest, SameSeedGivesIdenticalBytes) {
  const World a = World::Generate(SmallWorldOptions(), 42);
  const World& b = SmallWorld();
  ASSERT_EQ(a.terrain.heights_m().size(), b.terrain.heights_m().size());
  EXPECT_EQ(std::memcmp(a.terrain.heights_m().data(), b.terrain.heights_m().data(),
                        a.terrain.heights_m().size() * sizeof(float)),
            0);
  EXPECT_EQ(a.albedo.values, b.albedo.values);
  ASSERT_EQ(a.rocks.size(), b.rocks.size());
  for (std::size_t i = 0; i < a.rocks.size(); ++i) {
    EXPECT_EQ(a.rocks[i].center_xy, b.rocks[i].center_xy);
    EXPECT_EQ(a.rocks[i].surface_seed, b.rocks[i].surface_seed);
  }
  ASSERT_EQ(a.carriers.size(), b.carriers.size());
  for (std::size_t i = 0; i < a.carriers.size(); ++i) {
    EXPECT_EQ(a.carriers[i].T_world_carrier.matrix(), b.carriers[i].T_world_carrier.matrix());
  }
}

TEST(WorldTest, DifferentSeedGivesDifferentWorld) {
  const World a = World::Generate(SmallWorldOptions(), 43);
  const World& b = SmallWorld();
  std::size_t differing = 0;
  for (std::size_t i = 0; i < a.terrain.heights_m().size(); ++i) {
    differing += a.terrain.heights_m()[i] != b.terrain.heights_m()[i] ? 1U : 0U;
  }
  EXPECT_GT(differing, a.terrain.heights_m().size() * 9 / 10);
  EXPECT_NE(a.albedo.values, b.albedo.values);
  EXPECT_NE(a.craters[0].center_xy, b.craters[0].center_xy);
}

TEST(WorldTest, SmallWorldHasSlopesRocksCraterAndClearStart) {
  const World& world = SmallWorld();
  EXPECT_EQ(world.terrain.cols(), 801);
  EXPECT_EQ(world.terrain.rows(), 801);
  EXPECT_DOUBLE_EQ(world.terrain.origin_xy().x(), -20.0);
  const SlopeStats slopes = MeasureSlopes(world);
  EXPECT_LE(slopes.max_deg, 20.0 + 0.25);
  EXPECT_GE(slopes.max_deg, 8.0);
  EXPECT_GT(slopes.fraction_above_8_deg, 0.001);
  EXPECT_GE(world.rocks.size(), 70U);
  ExpectRocksValid(world);
  // Rocks do not overlap.
  for (std::size_t i = 0; i < world.rocks.size(); ++i) {
    for (std::size_t j = i + 1; j < world.rocks.size(); ++j) {
      EXPECT_GT((world.rocks[i].center_xy - world.rocks[j].center_xy).norm(),
                RockOuterRadius(world.rocks[i]) + RockOuterRadius(world.rocks[j]));
    }
  }
  ASSERT_EQ(world.craters.size(), 1U);
  EXPECT_GT(SmallestRimDrop(world, world.craters[0]), 0.3);
  // The start is clear and level enough to stand on: the origin is at height 0.
  EXPECT_NEAR(world.terrain.HeightAt(0.0, 0.0), 0.0, 1e-6);
  for (const Rock& rock : world.rocks) {
    EXPECT_GT(rock.center_xy.norm() - RockOuterRadius(rock), 3.0);
  }
  for (double x = -3.0; x <= 3.0; x += 0.05) {
    for (double y = -3.0; y <= 3.0; y += 0.05) {
      if (std::hypot(x, y) > 3.0) continue;
      for (const Rock& rock : world.rocks) ASSERT_EQ(RockBumpHeight(rock, x, y), 0.0);
    }
  }
}

TEST(WorldTest, RockBumpStaysWithinItsHeightAndOutline) {
  const World& world = SmallWorld();
  for (const Rock& rock : world.rocks) {
    const double outer = RockOuterRadius(rock);
    double peak = 0.0;
    for (double dx = -outer; dx <= outer; dx += 0.02) {
      for (double dy = -outer; dy <= outer; dy += 0.02) {
        const double bump = RockBumpHeight(rock, rock.center_xy.x() + dx, rock.center_xy.y() + dy);
        ASSERT_GE(bump, 0.0);
        ASSERT_LE(bump, rock.height_m);
        peak = std::max(peak, bump);
      }
    }
    EXPECT_GT(peak, 0.9 * rock.height_m);
    EXPECT_EQ(RockBumpHeight(rock, rock.center_xy.x() + outer, rock.center_xy.y()), 0.0);
  }
}

TEST(WorldTest, CraterProfileHasRimScarpAndBowl) {
  Crater crater;
  crater.center_xy = Eigen::Vector2d(3.0, -2.0);
  crater.radius_m = 6.0;
  crater.depth_m = 1.4;
  crater.rim_height_m = 0.4;
  crater.scarp_drop_m = 0.5;
  crater.scarp_width_m = 0.2;
  const auto at = [&](double d) { return CraterProfileHeight(crater, 3.0 + d, -2.0); };
  EXPECT_DOUBLE_EQ(at(0.0), -1.4);
  EXPECT_DOUBLE_EQ(at(6.0), 0.4);
  EXPECT_NEAR(at(5.8), -0.1, 1e-12);
  EXPECT_NEAR(at(5.8 - 1e-9), -0.1, 1e-6);  // the bowl meets the scarp foot
  EXPECT_EQ(at(15.0), 0.0);
  EXPECT_EQ(CraterOuterRadius(crater), 15.0);
  // The scarp is steeper than 60 degrees in its middle.
  EXPECT_GT((at(5.95) - at(5.85)) / 0.1, std::tan(60.0 / kDegPerRad));
}

TEST(WorldTest, PostsStandOnTheTerrainWithOutwardTags) {
  const World& world = SmallWorld();
  std::set<int> ids;
  int posts = 0;
  int rovers = 0;
  for (const TagCarrier& carrier : world.carriers) {
    for (const TagMarker& tag : carrier.tags) {
      EXPECT_TRUE(ids.insert(tag.id).second) << "duplicate id " << tag.id;
      EXPECT_GE(tag.id, 0);
      EXPECT_LT(tag.id, 587);
      EXPECT_EQ(tag.carrier, carrier.name);
      const Eigen::Matrix3d r = tag.T_carrier_tag.linear();
      EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 1e-12);
      EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
      // z points into the carrier: from the tag centre towards the carrier's
      // body, i.e. opposite to the outward direction from the body centre.
      const Eigen::Vector3d body_center = carrier.boxes.front().center_carrier;
      const Eigen::Vector3d head_center =
          carrier.is_static ? carrier.boxes[1].center_carrier : body_center;
      const Eigen::Vector3d outward = tag.T_carrier_tag.translation() - head_center;
      EXPECT_LT(r.col(2).dot(outward), -0.05) << carrier.name << " tag " << tag.id;
      // The tag's z is a face normal: exactly one carrier axis.
      EXPECT_NEAR(r.col(2).cwiseAbs().maxCoeff(), 1.0, 1e-12);
      // For the side tags, y (image down) points down in the carrier frame.
      if (std::abs(r.col(2).z()) < 0.5) {
        EXPECT_NEAR(r.col(1).z(), -1.0, 1e-12);
      }
    }
    if (carrier.is_static) {
      ++posts;
      ASSERT_EQ(carrier.tags.size(), 4U);
      const Eigen::Vector3d foot = carrier.T_world_carrier.translation();
      const double distance = foot.head<2>().norm();
      EXPECT_GE(distance, 5.0);
      EXPECT_LE(distance, 40.0);
      EXPECT_NEAR(foot.z(), world.terrain.HeightAt(foot.x(), foot.y()), 1e-9);
      EXPECT_NEAR(carrier.T_world_carrier.linear().col(2).z(), 1.0, 1e-12);
      for (const TagMarker& tag : carrier.tags) {
        const Eigen::Isometry3d T_world_tag = carrier.T_world_carrier * tag.T_carrier_tag;
        EXPECT_NEAR(T_world_tag.translation().z() - foot.z(), 0.8, 0.05);
        // Horizontal normals, all four directions.
        EXPECT_NEAR(T_world_tag.linear().col(2).z(), 0.0, 1e-12);
      }
      // The post stands clear of rocks.
      for (const Rock& rock : world.rocks) {
        EXPECT_GT((rock.center_xy - foot.head<2>()).norm(), RockOuterRadius(rock) + 0.5);
      }
    } else {
      ++rovers;
      ASSERT_EQ(carrier.tags.size(), 5U);
      const Box& body = carrier.boxes.front();
      EXPECT_NEAR(body.center_carrier.z() - 0.5 * body.size_m.z(), 0.15, 1e-12);
      EXPECT_EQ(body.size_m, Eigen::Vector3d(0.8, 0.6, 0.4));
      // One tag faces up.
      int up = 0;
      for (const TagMarker& tag : carrier.tags) {
        up += tag.T_carrier_tag.linear().col(2).z() < -0.99 ? 1 : 0;
      }
      EXPECT_EQ(up, 1);
    }
  }
  EXPECT_EQ(posts, 4);
  EXPECT_EQ(rovers, 2);
}

TEST(WorldTest, TagFacesAreReadableFromOutside) {
  // A camera 2 m in front of each post tag, looking at it, sees the tag frame
  // as the apriltag library reports it: z away from the camera, x right, y down.
  const World& world = SmallWorld();
  for (const TagCarrier& carrier : world.carriers) {
    if (!carrier.is_static) continue;
    for (const TagMarker& tag : carrier.tags) {
      const Eigen::Isometry3d T_world_tag = carrier.T_world_carrier * tag.T_carrier_tag;
      const Eigen::Vector3d z = T_world_tag.linear().col(2);
      const Eigen::Vector3d camera = T_world_tag.translation() - 2.0 * z;
      // The camera is outside the head box (farther from the post axis).
      const Eigen::Vector3d axis = carrier.T_world_carrier.translation();
      EXPECT_GT((camera - axis).head<2>().norm(),
                (T_world_tag.translation() - axis).head<2>().norm());
      // Camera frame looking along z with y down: x right is y x z.
      const Eigen::Vector3d down(0.0, 0.0, -1.0);
      EXPECT_LT((T_world_tag.linear().col(0) - down.cross(z)).norm(), 1e-12);
    }
  }
}

TEST(WorldTest, RejectsInvalidOptions) {
  WorldOptions options = SmallWorldOptions();
  options.resolution_m = 0.0;
  EXPECT_THROW(World::Generate(options, 1), std::invalid_argument);
  options = SmallWorldOptions();
  options.landmark_post_count = 200;  // 800 tags > 587 ids
  EXPECT_THROW(World::Generate(options, 1), std::invalid_argument);
  options = SmallWorldOptions();
  options.rock_count = -1;
  EXPECT_THROW(World::Generate(options, 1), std::invalid_argument);
}

// Standard deviation of the albedo (0..255) over square windows of `window`
// samples, averaged over `count` windows spread over the map.
double MeanLocalStd(const AlbedoMap& albedo, int window, int count) {
  std::mt19937_64 rng(9);
  std::uniform_int_distribution<int> corner(0, albedo.cols - window - 1);
  double sum = 0.0;
  for (int k = 0; k < count; ++k) {
    const int x0 = corner(rng);
    const int y0 = corner(rng);
    double s = 0.0;
    double s2 = 0.0;
    for (int iy = y0; iy < y0 + window; ++iy) {
      for (int ix = x0; ix < x0 + window; ++ix) {
        const double v =
            albedo.values[static_cast<std::size_t>(iy) * static_cast<std::size_t>(albedo.cols) +
                          static_cast<std::size_t>(ix)];
        s += v;
        s2 += v * v;
      }
    }
    const double n = window * window;
    sum += std::sqrt(std::max(0.0, s2 / n - (s / n) * (s / n)));
  }
  return sum / count;
}

// Standard deviation of the means of blocks of `block` samples: contrast at that scale and
// above, with everything finer averaged out.
double BlockMeanStd(const AlbedoMap& albedo, int block) {
  std::vector<double> means;
  for (int y0 = 0; y0 + block <= albedo.rows; y0 += block) {
    for (int x0 = 0; x0 + block <= albedo.cols; x0 += block) {
      double s = 0.0;
      for (int iy = y0; iy < y0 + block; ++iy) {
        for (int ix = x0; ix < x0 + block; ++ix) {
          s += albedo.values[static_cast<std::size_t>(iy) * static_cast<std::size_t>(albedo.cols) +
                             static_cast<std::size_t>(ix)];
        }
      }
      means.push_back(s / (block * block));
    }
  }
  double m = 0.0;
  for (double v : means) m += v;
  m /= static_cast<double>(means.size());
  double var = 0.0;
  for (double v : means) var += (v - m) * (v - m);
  return std::sqrt(var / static_cast<double>(means.size()));
}

TEST(WorldTest, AlbedoHasTextureAtSeveralScales) {
  const AlbedoMap& albedo = SmallWorld().albedo;
  ASSERT_EQ(albedo.cols, 1601);
  ASSERT_EQ(albedo.values.size(), 1601U * 1601U);
  const double res = albedo.resolution_m;
  const double grain = MeanLocalStd(albedo, static_cast<int>(std::lround(0.1 / res)), 4000);
  const double metre = BlockMeanStd(albedo, static_cast<int>(std::lround(1.0 / res)));
  const double five_metres = BlockMeanStd(albedo, static_cast<int>(std::lround(5.0 / res)));
  const double within_5m = MeanLocalStd(albedo, static_cast<int>(std::lround(5.0 / res)), 40);
  std::printf(
      "albedo std: 10 cm windows %.1f, 1 m block means %.1f, 5 m block means %.1f, "
      "5 m windows %.1f (grey levels)\n",
      grain, metre, five_metres, within_5m);
  EXPECT_GT(grain, 4.0);
  EXPECT_GT(metre, 6.0);
  EXPECT_GT(five_metres, 4.0);
  EXPECT_GT(within_5m, 8.0);
  // Bilinear lookup reproduces the samples.
  EXPECT_NEAR(albedo.At(albedo.origin_xy.x() + 3 * res, albedo.origin_xy.y() + 5 * res),
              albedo.values[5 * 1601 + 3] / 255.0, 1e-12);
  EXPECT_GE(albedo.At(-100.0, 100.0), 0.0);
  EXPECT_LE(albedo.At(-100.0, 100.0), 1.0);
}

// Renders the bare albedo as a camera 0.6 m above flat ground would see it (90 degree
// horizontal field of view, 752 x 480, pitched 15 degrees down, 2 x 2 supersampling) and
// counts Shi-Tomasi corners in the image bands that show the ground 1-3 m, 3-8 m and 8-20 m
// away: the texture alone must offer features at every range.
TEST(WorldTest, AlbedoGivesCornersFromOneToTwentyMetres) {
  const World& world = SmallWorld();
  const int width = 752;
  const int height = 480;
  const double f = 0.5 * width;  // 90 degrees horizontally
  const double pitch = 15.0 / kDegPerRad;
  const double camera_z = 0.6;
  cv::Mat image(height, width, CV_8UC1);
  cv::Mat distance = cv::Mat::zeros(height, width, CV_32FC1);
  for (int r = 0; r < height; ++r) {
    for (int c = 0; c < width; ++c) {
      double sum = 0.0;
      for (int s = 0; s < 4; ++s) {
        const double u = c + 0.25 + 0.5 * (s % 2);
        const double v = r + 0.25 + 0.5 * (s / 2);
        // Camera looking along +x (y left, z up), rays pitched down.
        const double right = (u - 0.5 * width) / f;
        const double down = (v - 0.5 * height) / f;
        const double fwd = std::cos(pitch) - down * std::sin(pitch);
        const double dz = -std::sin(pitch) - down * std::cos(pitch);
        if (dz >= -1e-6) continue;
        const double t = camera_z / -dz;
        sum += world.albedo.At(2.0 + t * fwd, 1.0 - t * right);
        if (s == 0) distance.at<float>(r, c) = static_cast<float>(t * fwd);
      }
      image.at<uint8_t>(r, c) = static_cast<uint8_t>(std::lround(255.0 * sum / 4.0));
    }
  }
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(image, corners, 2000, 0.01, 5.0);
  int near = 0;
  int middle = 0;
  int far = 0;
  for (const cv::Point2f& p : corners) {
    const float d = distance.at<float>(static_cast<int>(p.y), static_cast<int>(p.x));
    near += d >= 1.0F && d < 3.0F ? 1 : 0;
    middle += d >= 3.0F && d < 8.0F ? 1 : 0;
    far += d >= 8.0F && d <= 20.0F ? 1 : 0;
  }
  std::printf("corners: %d at 1-3 m, %d at 3-8 m, %d at 8-20 m\n", near, middle, far);
  EXPECT_GE(near, 30);
  EXPECT_GE(middle, 30);
  EXPECT_GE(far, 10);
}

TEST(WorldTest, PlacedPostsStandWhereTheScenarioSaysAndTheRestAreRandom) {
  WorldOptions options = SmallWorldOptions();
  options.landmark_post_count = 3;
  options.landmark_posts_xy_m = {Eigen::Vector2d(6.0, -2.0), Eigen::Vector2d(-4.0, 5.0)};
  const World world = World::Generate(options, 7);
  ASSERT_GE(world.carriers.size(), 3u);
  EXPECT_TRUE(world.carriers[0].T_world_carrier.translation().head<2>().isApprox(
      Eigen::Vector2d(6.0, -2.0)));
  EXPECT_TRUE(world.carriers[1].T_world_carrier.translation().head<2>().isApprox(
      Eigen::Vector2d(-4.0, 5.0)));
  EXPECT_NEAR(world.carriers[0].T_world_carrier.translation().z(),
              world.terrain.HeightAt(6.0, -2.0), 1e-9);
  EXPECT_TRUE(world.carriers[2].is_static);
  EXPECT_FALSE(world.carriers[2].T_world_carrier.translation().head<2>().isApprox(
      Eigen::Vector2d(6.0, -2.0)));
}

TEST(WorldTest, TheTagMarkerFileNamesEveryTagWithItsCarrier) {
  const World& world = SmallWorld();
  const std::string file = TagMarkerFile(world);
  std::size_t posts = 0;
  std::size_t tags = 0;
  for (const TagCarrier& c : world.carriers) {
    posts += c.is_static;
    tags += c.tags.size();
  }
  ASSERT_GT(posts, 0u);
  // One line per tag, each with its carrier's name.
  std::size_t lines = 0;
  for (std::size_t at = file.find("  - {id: "); at != std::string::npos;
       at = file.find("  - {id: ", at + 1)) {
    ++lines;
  }
  EXPECT_EQ(lines, tags);
  EXPECT_NE(file.find("landmark: 0, T_carrier_tag: ["), std::string::npos) << file;
  EXPECT_NE(file.find("robot: 1, T_carrier_tag: ["), std::string::npos) << file;
  EXPECT_NE(file.find("families: [tag36h11]"), std::string::npos);
  // mapd reads it: the first post's second tag, with its pose on the post.
  const mapping::TagObserverOptions options =
      mapping::TagObserverOptions::Load(ConfigNode::LoadString(file, "tags.yaml"));
  ASSERT_EQ(options.markers.size(), tags);
  const TagMarker& tag = world.carriers[0].tags[1];
  const mapping::TagMarker& marker = options.markers[1];
  EXPECT_EQ(marker.id, tag.id);
  EXPECT_DOUBLE_EQ(marker.size_m, tag.size_m);
  EXPECT_EQ(marker.carrier, mapping::TagMarker::Carrier::kLandmark);
  EXPECT_EQ(marker.landmark, 0);
  EXPECT_TRUE(marker.T_carrier_tag.isApprox(tag.T_carrier_tag, 1e-12));
  EXPECT_EQ(options.markers.back().carrier, mapping::TagMarker::Carrier::kRobot);
}

// A robot marker is where the other rover's filter puts its body: the
// carrier frame (ground level) moved up by the rover's body height.
TEST(WorldTest, RobotMarkersAreInTheRoversBodyFrame) {
  const World& world = SmallWorld();
  const mapping::TagObserverOptions in_body = mapping::TagObserverOptions::Load(
      ConfigNode::LoadString(TagMarkerFile(world, {{1, 0.35}}), "tags.yaml"));
  const mapping::TagObserverOptions in_carrier =
      mapping::TagObserverOptions::Load(ConfigNode::LoadString(TagMarkerFile(world), "tags.yaml"));
  ASSERT_EQ(in_body.markers.size(), in_carrier.markers.size());
  int robot_markers = 0;
  for (std::size_t k = 0; k < in_body.markers.size(); ++k) {
    const mapping::TagMarker& b = in_body.markers[k];
    const mapping::TagMarker& c = in_carrier.markers[k];
    const double dz = b.T_carrier_tag.translation().z() - c.T_carrier_tag.translation().z();
    if (b.carrier == mapping::TagMarker::Carrier::kRobot && b.robot == 1) {
      EXPECT_NEAR(dz, -0.35, 1e-12);
      ++robot_markers;
    } else {
      EXPECT_EQ(dz, 0.0);
    }
  }
  EXPECT_GT(robot_markers, 0);
}

}  // namespace
}  // namespace rover::sim
