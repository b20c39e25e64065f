#include "estimator/eval/tum_trajectory.h"

#include <cmath>
#include <fstream>
#include <vector>

#include "estimator/eval/eval_error.h"
#include "estimator/eval/number_format.h"
#include "estimator/eval/text_table_reader.h"

namespace rover::eval {

Trajectory ReadTumTrajectory(const std::string& path) {
  TextTableReader reader(path, TextTableReader::Separator::kWhitespace);
  Trajectory trajectory;
  trajectory.set_source(path);
  std::vector<std::string_view> c;
  while (reader.Next(&c)) {
    if (c.size() < 8) {
      reader.Fail("expected 8 columns (timestamp tx ty tz qx qy qz qw), found " +
                  std::to_string(c.size()) + (c.size() == 1 ? " (is it a CSV?)" : ""));
    }
    PoseSample s;
    s.stamp = reader.Seconds(c[0], "timestamp");
    s.p_world_body = {reader.Double(c[1], "tx"), reader.Double(c[2], "ty"),
                      reader.Double(c[3], "tz")};
    s.q_world_body = Eigen::Quaterniond(reader.Double(c[7], "qw"), reader.Double(c[4], "qx"),
                                        reader.Double(c[5], "qy"), reader.Double(c[6], "qz"));
    const double norm = s.q_world_body.norm();
    if (std::abs(norm - 1.0) > 1e-3) {
      reader.Fail("expected a unit quaternion (norm 1 +- 1e-3), found norm " + FormatDouble(norm));
    }
    s.q_world_body = UnitQuaternion(s.q_world_body);
    if (!trajectory.empty() && s.stamp <= trajectory.samples().back().stamp) {
      reader.Fail("expected the timestamp to increase, found " + FormatSeconds(s.stamp) +
                  " s after " + FormatSeconds(trajectory.samples().back().stamp) + " s");
    }
    trajectory.Append(s);
  }
  if (trajectory.empty()) throw EvalError(path + ": expected trajectory rows, found none");
  return trajectory;
}

void WriteTumTrajectory(const Trajectory& trajectory, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw EvalError(path + ": cannot open for writing");
  out << "# timestamp tx ty tz qx qy qz qw\n";
  for (const PoseSample& s : trajectory) {
    out << FormatSeconds(s.stamp);
    for (int i = 0; i < 3; ++i) out << ' ' << FormatDouble(s.p_world_body[i]);
    for (const double q :
         {s.q_world_body.x(), s.q_world_body.y(), s.q_world_body.z(), s.q_world_body.w()}) {
      out << ' ' << FormatDouble(q);
    }
    out << '\n';
  }
  out.flush();
  if (!out) throw EvalError(path + ": write failed");
}

}  // namespace rover::eval
