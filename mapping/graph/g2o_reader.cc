#include "mapping/graph/g2o_reader.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string_view>
#include <vector>

#include <Eigen/Eigenvalues>

namespace rover::mapping {
namespace {

std::vector<std::string_view> SplitWhitespace(std::string_view line) {
  std::vector<std::string_view> tokens;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
  return tokens;
}

class LineParser {
 public:
  LineParser(const std::string& source, int line, std::vector<std::string_view> tokens)
      : source_(source), line_(line), tokens_(std::move(tokens)) {}

  [[noreturn]] void Fail(const std::string& message) const {
    throw GraphError(source_ + ":" + std::to_string(line_) + ": " + message);
  }

  void ExpectFields(size_t count) const {
    if (tokens_.size() != count) {
      Fail("expected " + std::to_string(count - 1) + " values after " + std::string(tokens_[0]) +
           ", found " + std::to_string(tokens_.size() - 1));
    }
  }

  double Number(size_t index, const char* what) const {
    const std::string_view token = tokens_[index];
    double value = 0.0;
    const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc() || ptr != token.data() + token.size()) {
      Fail(std::string("expected a number for ") + what + ", found '" + std::string(token) + "'");
    }
    if (!std::isfinite(value)) {
      Fail(std::string("expected a finite number for ") + what + ", found '" + std::string(token) +
           "' (NaN input)");
    }
    return value;
  }

  int64_t Id(size_t index, const char* what) const {
    const std::string_view token = tokens_[index];
    int64_t value = 0;
    const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc() || ptr != token.data() + token.size() || value < 0) {
      Fail(std::string("expected a non-negative integer ") + what + ", found '" +
           std::string(token) + "'");
    }
    return value;
  }

  Eigen::Quaterniond Quaternion(size_t first) const {
    const Eigen::Quaterniond q(Number(first + 3, "qw"), Number(first, "qx"),
                               Number(first + 1, "qy"), Number(first + 2, "qz"));
    if (q.norm() < 1e-9) Fail("expected a unit quaternion, found one of norm ~0");
    return q.normalized();
  }

  // Reads n*(n+1)/2 upper-triangular entries, row by row. The translation
  // block (first N/2 rows: x, y[, z]) and the rotation block (the rest) must
  // each be positive definite: every objective needs them. The matrix as a
  // whole may be indefinite (some published datasets carry such matrices);
  // whether that is acceptable depends on the objective (CheckInformation).
  template <int N>
  Eigen::Matrix<double, N, N> UpperTriangular(size_t first) const {
    Eigen::Matrix<double, N, N> I;
    size_t k = first;
    for (int r = 0; r < N; ++r) {
      for (int c = r; c < N; ++c) {
        I(r, c) = I(c, r) = Number(k++, "an information entry");
      }
    }
    constexpr int kTranslation = N == 6 ? 3 : 2;
    ExpectPositiveDefinite(I.topLeftCorner(kTranslation, kTranslation),
                           N == 6 ? "translation block (x, y, z)" : "translation block (x, y)");
    ExpectPositiveDefinite(I.bottomRightCorner(N - kTranslation, N - kTranslation),
                           N == 6 ? "rotation block (qx, qy, qz)" : "rotation entry (theta)");
    return I;
  }

  void ExpectPositiveDefinite(const Eigen::MatrixXd& block, const char* what) const {
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(block);
    const double min_eigenvalue = eig.eigenvalues()(0);
    if (!(min_eigenvalue > 0.0)) {
      std::ostringstream os;
      os << "expected a positive-definite " << what
         << " of the information matrix, found one with smallest eigenvalue " << min_eigenvalue;
      Fail(os.str());
    }
  }

 private:
  const std::string& source_;
  int line_;
  std::vector<std::string_view> tokens_;
};

}  // namespace

PoseGraph ReadG2o(std::istream& in, const std::string& source_name) {
  PoseGraph graph;
  graph.source = source_name;
  int dimension = 0;
  int dimension_line = 0;
  std::map<int64_t, int> vertex_line;
  std::string text;
  int line = 0;
  auto set_dimension = [&](int d, const LineParser& parser) {
    if (dimension == 0) {
      dimension = d;
      dimension_line = line;
    } else if (dimension != d) {
      parser.Fail("expected a " + std::to_string(dimension) + "D record (as on line " +
                  std::to_string(dimension_line) + "), found a " + std::to_string(d) + "D one");
    }
  };
  while (std::getline(in, text)) {
    ++line;
    const std::vector<std::string_view> tokens = SplitWhitespace(text);
    if (tokens.empty() || tokens[0][0] == '#') continue;
    const LineParser p(graph.source, line, tokens);
    const std::string_view tag = tokens[0];
    if (tag == "VERTEX_SE3:QUAT") {
      set_dimension(3, p);
      p.ExpectFields(9);
      PoseVertex v;
      v.id = p.Id(1, "vertex id");
      v.pose.translation() = Eigen::Vector3d(p.Number(2, "x"), p.Number(3, "y"), p.Number(4, "z"));
      v.pose.linear() = p.Quaternion(5).toRotationMatrix();
      if (!vertex_line.emplace(v.id, line).second) {
        p.Fail("expected a new vertex id, found " + std::to_string(v.id) +
               " already defined on line " + std::to_string(vertex_line[v.id]));
      }
      graph.vertices.push_back(v);
    } else if (tag == "VERTEX_SE2") {
      set_dimension(2, p);
      p.ExpectFields(5);
      PoseVertex v;
      v.id = p.Id(1, "vertex id");
      v.pose = PoseFromPlanar(p.Number(2, "x"), p.Number(3, "y"), p.Number(4, "theta"));
      if (!vertex_line.emplace(v.id, line).second) {
        p.Fail("expected a new vertex id, found " + std::to_string(v.id) +
               " already defined on line " + std::to_string(vertex_line[v.id]));
      }
      graph.vertices.push_back(v);
    } else if (tag == "EDGE_SE3:QUAT") {
      set_dimension(3, p);
      p.ExpectFields(3 + 7 + 21);
      PoseEdge e;
      e.line = line;
      e.from = p.Id(1, "vertex id");
      e.to = p.Id(2, "vertex id");
      e.measurement.translation() =
          Eigen::Vector3d(p.Number(3, "x"), p.Number(4, "y"), p.Number(5, "z"));
      e.measurement.linear() = p.Quaternion(6).toRotationMatrix();
      e.information = p.UpperTriangular<6>(10);
      graph.edges.push_back(e);
    } else if (tag == "EDGE_SE2") {
      set_dimension(2, p);
      p.ExpectFields(3 + 3 + 6);
      PoseEdge e;
      e.line = line;
      e.from = p.Id(1, "vertex id");
      e.to = p.Id(2, "vertex id");
      e.measurement = PoseFromPlanar(p.Number(3, "x"), p.Number(4, "y"), p.Number(5, "theta"));
      const Eigen::Matrix3d I = p.UpperTriangular<3>(6);
      e.information.setZero();
      const int idx[3] = {0, 1, 5};
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) e.information(idx[r], idx[c]) = I(r, c);
      }
      graph.edges.push_back(e);
    } else if (tag == "FIX") {
      if (tokens.size() < 2) p.Fail("expected a vertex id after FIX, found nothing");
      for (size_t i = 1; i < tokens.size(); ++i) (void)p.Id(i, "vertex id");
    } else {
      p.Fail("expected VERTEX_SE3:QUAT, EDGE_SE3:QUAT, VERTEX_SE2, EDGE_SE2 or FIX, found '" +
             std::string(tag) + "'");
    }
  }
  if (in.bad()) throw GraphError(graph.source + ": read error");
  if (dimension == 0) {
    throw GraphError(graph.source + ":" + std::to_string(line) +
                     ": expected at least one vertex or edge, found none");
  }
  graph.dimension = dimension;

  for (const PoseEdge& e : graph.edges) {
    const std::string where = graph.source + ":" + std::to_string(e.line) + ": ";
    if (e.from == e.to) {
      throw GraphError(where + "expected an edge between two vertices, found a self-loop on " +
                       std::to_string(e.from));
    }
    if (!graph.vertices.empty()) {
      for (const int64_t id : {e.from, e.to}) {
        if (vertex_line.find(id) == vertex_line.end()) {
          throw GraphError(where + "edge " + std::to_string(e.from) + " -> " +
                           std::to_string(e.to) + " references vertex " + std::to_string(id) +
                           ", which no VERTEX line defines");
        }
      }
    }
  }
  if (graph.vertices.empty()) {
    graph.vertices_implied = true;
    std::set<int64_t> ids;
    for (const PoseEdge& e : graph.edges) {
      ids.insert(e.from);
      ids.insert(e.to);
    }
    for (const int64_t id : ids) {
      PoseVertex v;
      v.id = id;
      graph.vertices.push_back(v);
    }
  }
  return graph;
}

PoseGraph ReadG2oFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw GraphError(path + ": cannot open file");
  return ReadG2o(in, path);
}

}  // namespace rover::mapping
