// Geometry of the tag carriers: landmark posts and other rovers.

#include <string>

#include "hil/sim/world/world.h"

namespace rover::sim {
namespace {

// Tags stand this far in front of their face, so a renderer never has the
// tag and the face at the same depth.
constexpr double kTagStandoffM = 0.001;

// A tag centred at `center` on a face whose outward normal is `outward`, read
// by a camera outside: z into the face, y along `down` (image down), x = y x z.
TagMarker MakeTag(int id, double size_m, const std::string& carrier, const Eigen::Vector3d& center,
                  const Eigen::Vector3d& outward, const Eigen::Vector3d& down) {
  TagMarker tag;
  tag.id = id;
  tag.size_m = size_m;
  tag.carrier = carrier;
  const Eigen::Vector3d z = -outward;
  const Eigen::Vector3d y = down;
  const Eigen::Vector3d x = y.cross(z);
  tag.T_carrier_tag.linear().col(0) = x;
  tag.T_carrier_tag.linear().col(1) = y;
  tag.T_carrier_tag.linear().col(2) = z;
  tag.T_carrier_tag.translation() = center + kTagStandoffM * outward;
  return tag;
}

}  // namespace

TagCarrier MakeLandmarkPost(const std::string& name, int first_tag_id, double tag_size_m,
                            const Eigen::Isometry3d& T_world_carrier) {
  constexpr double kHeadCenterZ = 0.8;
  constexpr double kPoleSide = 0.08;
  constexpr double kBuriedM = 0.1;  // the pole reaches into the ground on slopes
  // The head is a cube just wider than the full tag image (1.25 x the
  // black-square size), so the four tags never overlap at the corners as they
  // would on the bare 8 cm pole.
  const double head_side = 1.25 * tag_size_m + 0.02;
  const double head_bottom = kHeadCenterZ - 0.5 * head_side;

  TagCarrier post;
  post.name = name;
  post.is_static = true;
  post.T_world_carrier = T_world_carrier;
  post.boxes.push_back({Eigen::Vector3d(0.0, 0.0, 0.5 * (head_bottom - kBuriedM)),
                        Eigen::Vector3d(kPoleSide, kPoleSide, head_bottom + kBuriedM), 0.3});
  post.boxes.push_back({Eigen::Vector3d(0.0, 0.0, kHeadCenterZ),
                        Eigen::Vector3d(head_side, head_side, head_side), 0.9});
  const Eigen::Vector3d down(0.0, 0.0, -1.0);
  const Eigen::Vector3d outward[4] = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                      -Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitY()};
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d center =
        Eigen::Vector3d(0.0, 0.0, kHeadCenterZ) + 0.5 * head_side * outward[k];
    post.tags.push_back(MakeTag(first_tag_id + k, tag_size_m, name, center, outward[k], down));
  }
  return post;
}

TagCarrier MakeOtherRover(const std::string& name, int first_tag_id, double tag_size_m) {
  constexpr double kLength = 0.8;
  constexpr double kWidth = 0.6;
  constexpr double kHeight = 0.4;
  constexpr double kClearance = 0.15;
  constexpr double kBodyCenterZ = kClearance + 0.5 * kHeight;
  constexpr double kTopZ = kClearance + kHeight;

  TagCarrier rover;
  rover.name = name;
  rover.is_static = false;
  rover.boxes.push_back(
      {Eigen::Vector3d(0.0, 0.0, kBodyCenterZ), Eigen::Vector3d(kLength, kWidth, kHeight), 0.75});
  // Wheels outside the body, clear of the side tags' x extent.
  for (double x : {0.3, -0.3}) {
    for (double y : {0.36, -0.36}) {
      rover.boxes.push_back({Eigen::Vector3d(x, y, 0.13), Eigen::Vector3d(0.26, 0.1, 0.26), 0.2});
    }
  }
  // Camera mast near the front, clear of the top tag.
  rover.boxes.push_back(
      {Eigen::Vector3d(0.25, 0.0, kTopZ + 0.25), Eigen::Vector3d(0.05, 0.05, 0.5), 0.4});
  rover.boxes.push_back(
      {Eigen::Vector3d(0.25, 0.0, kTopZ + 0.53), Eigen::Vector3d(0.08, 0.3, 0.06), 0.25});

  const Eigen::Vector3d down(0.0, 0.0, -1.0);
  rover.tags.push_back(MakeTag(first_tag_id, tag_size_m, name,
                               Eigen::Vector3d(0.5 * kLength, 0.0, kBodyCenterZ),
                               Eigen::Vector3d::UnitX(), down));
  rover.tags.push_back(MakeTag(first_tag_id + 1, tag_size_m, name,
                               Eigen::Vector3d(0.0, 0.5 * kWidth, kBodyCenterZ),
                               Eigen::Vector3d::UnitY(), down));
  rover.tags.push_back(MakeTag(first_tag_id + 2, tag_size_m, name,
                               Eigen::Vector3d(-0.5 * kLength, 0.0, kBodyCenterZ),
                               -Eigen::Vector3d::UnitX(), down));
  rover.tags.push_back(MakeTag(first_tag_id + 3, tag_size_m, name,
                               Eigen::Vector3d(0.0, -0.5 * kWidth, kBodyCenterZ),
                               -Eigen::Vector3d::UnitY(), down));
  // On top, read from above with the rover's front at the top of the image.
  rover.tags.push_back(MakeTag(first_tag_id + 4, tag_size_m, name,
                               Eigen::Vector3d(-0.1, 0.0, kTopZ), Eigen::Vector3d::UnitZ(),
                               -Eigen::Vector3d::UnitX()));
  return rover;
}

}  // namespace rover::sim
