#include "mapping/graph/helmert_block_solver.h"

#include <ceres/cost_function.h>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <thread>
#include <utility>

#include "mapping/graph/chordal_pose_2d_cost.h"
#include "mapping/graph/chordal_pose_3d_cost.h"
#include "mapping/graph/graph_connectivity.h"
#include "mapping/graph/pose_manifold.h"
#include "mapping/graph/relative_pose_2d_cost.h"
#include "mapping/graph/relative_pose_3d_cost.h"
#include "mapping/graph/se_sync_objective.h"

namespace rover::mapping {
namespace {

using Clock = std::chrono::steady_clock;
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using SparseLlt =
    Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>>;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// Runs fn(0..n-1) on up to `threads` threads (work stealing by an atomic index).
template <typename Fn>
void ParallelFor(int n, int threads, const Fn& fn) {
  const int t = std::max(1, std::min(threads, n));
  std::atomic<int> next{0};
  auto worker = [&] {
    for (int k = next++; k < n; k = next++) fn(k);
  };
  std::vector<std::thread> pool;
  for (int i = 1; i < t; ++i) pool.emplace_back(worker);
  worker();
  for (std::thread& th : pool) th.join();
}

template <typename Matrix>
std::size_t FactorBytes(const Matrix& L) {
  return static_cast<std::size_t>(L.nonZeros()) * (sizeof(double) + sizeof(int)) +
         static_cast<std::size_t>(L.cols() + 1) * sizeof(int);
}

// Residuals and tangent Jacobians of every edge of a g2o graph for one
// objective; the vertex parameters are the solver's layout (2D: x, y, theta;
// 3D: PoseManifold's 7 doubles, tangent [dt; dphi]).
class Model {
 public:
  Model(const PoseGraph& graph, Objective objective)
      : planar_(graph.dimension == 2), dim_(planar_ ? 3 : 6), stride_(planar_ ? 3 : 7) {
    const auto index = VertexIndex(graph);
    for (const PoseEdge& e : graph.edges) {
      ends_.emplace_back(index.at(e.from), index.at(e.to));
      costs_.push_back(MakeCost(graph, e, objective));
    }
  }

  int dim() const { return dim_; }
  int stride() const { return stride_; }
  std::size_t edges() const { return ends_.size(); }
  std::pair<int, int> ends(std::size_t k) const { return ends_[k]; }
  int residuals(std::size_t k) const { return costs_[k]->num_residuals(); }

  std::vector<double> ToParameters(const PoseGraph& graph) const {
    std::vector<double> x(graph.vertices.size() * static_cast<std::size_t>(stride_));
    for (std::size_t v = 0; v < graph.vertices.size(); ++v) {
      double* b = x.data() + v * static_cast<std::size_t>(stride_);
      if (planar_) {
        const Eigen::Vector3d p = PlanarPose(graph.vertices[v].pose);
        std::copy(p.data(), p.data() + 3, b);
      } else {
        PoseToParameters(graph.vertices[v].pose, b);
      }
    }
    return x;
  }

  void FromParameters(const std::vector<double>& x, PoseGraph& graph) const {
    for (std::size_t v = 0; v < graph.vertices.size(); ++v) {
      const double* b = x.data() + v * static_cast<std::size_t>(stride_);
      graph.vertices[v].pose =
          planar_ ? PoseFromPlanar(b[0], b[1], WrapAngle(b[2])) : PoseFromParameters(b);
    }
  }

  // x_out = x Plus delta for vertex v.
  void Plus(const double* x, const double* delta, double* out) const {
    if (planar_) {
      for (int i = 0; i < 3; ++i) out[i] = x[i] + delta[i];
    } else {
      manifold_.Plus(x, delta, out);
    }
  }

  // Residual r (m) and tangent Jacobians Ji, Jj (m x dim) of edge k.
  void Linearise(std::size_t k, const std::vector<double>& x, Eigen::VectorXd& r,
                 Eigen::MatrixXd& Ji, Eigen::MatrixXd& Jj) const {
    const int m = costs_[k]->num_residuals();
    const double* params[2] = {Block(x, ends_[k].first), Block(x, ends_[k].second)};
    RowMatrix ji(m, stride_);
    RowMatrix jj(m, stride_);
    double* jac[2] = {ji.data(), jj.data()};
    r.resize(m);
    costs_[k]->Evaluate(params, r.data(), jac);
    Ji = ji.leftCols(dim_);
    Jj = jj.leftCols(dim_);
  }

  // 0.5 sum |r|^2.
  double Cost(const std::vector<double>& x) const {
    double sum = 0.0;
    Eigen::VectorXd r;
    for (std::size_t k = 0; k < costs_.size(); ++k) {
      const double* params[2] = {Block(x, ends_[k].first), Block(x, ends_[k].second)};
      r.resize(costs_[k]->num_residuals());
      costs_[k]->Evaluate(params, r.data(), nullptr);
      sum += r.squaredNorm();
    }
    return 0.5 * sum;
  }

 private:
  const double* Block(const std::vector<double>& x, int v) const {
    return x.data() + static_cast<std::size_t>(v) * static_cast<std::size_t>(stride_);
  }

  static std::unique_ptr<ceres::CostFunction> MakeCost(const PoseGraph& graph, const PoseEdge& e,
                                                       Objective objective) {
    const bool planar = graph.dimension == 2;
    if (objective == Objective::kSeSync) {
      const IsotropicWeights w = SeSyncWeights(e, graph.dimension);
      if (planar) {
        return std::make_unique<ChordalPose2dCost>(PlanarPose(e.measurement), w.kappa, w.tau);
      }
      return std::make_unique<ChordalPose3dCost>(e.measurement, w.kappa, w.tau);
    }
    if (planar) {
      return std::make_unique<RelativePose2dCost>(PlanarPose(e.measurement),
                                                  PlanarInformation(e.information));
    }
    return std::make_unique<RelativePose3dCost>(e.measurement, e.information);
  }

  bool planar_;
  int dim_;
  int stride_;
  PoseManifold manifold_;
  std::vector<std::pair<int, int>> ends_;
  std::vector<std::unique_ptr<ceres::CostFunction>> costs_;
};

// Where a free vertex lives: its block, whether it is a separator, its index
// among its block's interior (or separator) vertices, and (separators) its
// index in the reduced system.
struct VertexRole {
  int block = -1;
  bool separator = false;
  int local = -1;
  int global = -1;
};

struct Block {
  std::vector<int> interior;
  std::vector<int> separators;
  std::vector<std::size_t> edges;  // Edges whose free ends are all in this block.
  // Per iteration:
  Eigen::MatrixXd X;       // H_II^-1 H_IS
  Eigen::VectorXd y;       // H_II^-1 b_I
  Eigen::MatrixXd S;       // H_SS - H_SI X (undamped separator part)
  Eigen::VectorXd c;       // b_S - H_SI y
  Eigen::VectorXd diag_s;  // diag(H_SS) of this block's edges
  Eigen::VectorXd b_i;     // b_I (for the LM gain ratio)
  Eigen::VectorXd b_s;     // b_S before the reduction
  Eigen::VectorXd damp_i;  // max(diag(H_II), 1e-6)
  std::size_t bytes = 0;
  bool ok = true;
};

}  // namespace

std::vector<int> PartitionVertices(const PoseGraph& graph, HelmertPartition partition,
                                   int block_size) {
  const int n = static_cast<int>(graph.vertices.size());
  const int size = std::max(1, block_size);
  std::vector<int> block(static_cast<std::size_t>(n), 0);
  if (partition == HelmertPartition::kContiguous) {
    for (int v = 0; v < n; ++v) block[static_cast<std::size_t>(v)] = v / size;
    return block;
  }
  // Recursive coordinate bisection, iteratively over a stack of ranges of
  // `order`.
  std::vector<int> order(static_cast<std::size_t>(n));
  for (int v = 0; v < n; ++v) order[static_cast<std::size_t>(v)] = v;
  auto position = [&](int v) -> Eigen::Vector3d {
    return graph.vertices[static_cast<std::size_t>(v)].pose.translation();
  };
  std::vector<std::pair<int, int>> stack{{0, n}};
  int next = 0;
  while (!stack.empty()) {
    const auto [lo, hi] = stack.back();
    stack.pop_back();
    if (hi - lo <= size) {
      for (int k = lo; k < hi; ++k)
        block[static_cast<std::size_t>(order[static_cast<std::size_t>(k)])] = next;
      ++next;
      continue;
    }
    Eigen::Vector3d min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d max = -min;
    for (int k = lo; k < hi; ++k) {
      min = min.cwiseMin(position(order[static_cast<std::size_t>(k)]));
      max = max.cwiseMax(position(order[static_cast<std::size_t>(k)]));
    }
    int axis = 0;
    (max - min).maxCoeff(&axis);
    const int mid = lo + (hi - lo) / 2;
    std::nth_element(order.begin() + lo, order.begin() + mid, order.begin() + hi,
                     [&](int a, int b) { return position(a)(axis) < position(b)(axis); });
    stack.emplace_back(mid, hi);
    stack.emplace_back(lo, mid);
  }
  return block;
}

HelmertBlockSolver::HelmertBlockSolver(HelmertBlockOptions options)
    : options_(std::move(options)) {}

HelmertBlockSummary HelmertBlockSolver::Solve(PoseGraph& graph) const {
  CheckGaugeAndFinite(graph);
  (void)CheckInformation(graph, options_.objective);
  const Clock::time_point start = Clock::now();
  HelmertBlockSummary out;
  const Model model(graph, options_.objective);
  const int d = model.dim();
  const int n = static_cast<int>(graph.vertices.size());

  // Partition. Vertex 0 is fixed and belongs to no block.
  std::vector<VertexRole> role(static_cast<std::size_t>(n));
  const std::vector<int> partition =
      options_.block_of_vertex.empty()
          ? PartitionVertices(graph, options_.partition, options_.block_size)
          : options_.block_of_vertex;
  if (static_cast<int>(partition.size()) != n) {
    throw GraphError("HelmertBlockSolver: block_of_vertex needs one entry per vertex");
  }
  int num_blocks = 0;
  for (int v = 1; v < n; ++v) {
    const int b = partition[static_cast<std::size_t>(v)];
    if (b < 0) throw GraphError("HelmertBlockSolver: negative block index");
    role[static_cast<std::size_t>(v)].block = b;
    num_blocks = std::max(num_blocks, b + 1);
  }
  std::vector<std::size_t> cross_edges;
  std::vector<std::size_t> edge_block(model.edges(), 0);
  for (std::size_t k = 0; k < model.edges(); ++k) {
    const auto [i, j] = model.ends(k);
    if (i != 0 && j != 0 &&
        role[static_cast<std::size_t>(i)].block != role[static_cast<std::size_t>(j)].block) {
      role[static_cast<std::size_t>(i)].separator = true;
      role[static_cast<std::size_t>(j)].separator = true;
      cross_edges.push_back(k);
    }
  }
  std::vector<Block> blocks(static_cast<std::size_t>(num_blocks));
  int num_separators = 0;
  for (int v = 1; v < n; ++v) {
    VertexRole& r = role[static_cast<std::size_t>(v)];
    Block& b = blocks[static_cast<std::size_t>(r.block)];
    if (r.separator) {
      r.local = static_cast<int>(b.separators.size());
      r.global = num_separators++;
      b.separators.push_back(v);
      ++out.separator_vertices;
    } else {
      r.local = static_cast<int>(b.interior.size());
      b.interior.push_back(v);
      ++out.interior_vertices;
    }
  }
  for (std::size_t k = 0; k < model.edges(); ++k) {
    const auto [i, j] = model.ends(k);
    const int free_end = i != 0 ? i : j;
    if (free_end == 0) continue;  // A self-loop on the anchor: constant.
    const int bi = i != 0 ? role[static_cast<std::size_t>(i)].block : -1;
    const int bj = j != 0 ? role[static_cast<std::size_t>(j)].block : -1;
    if (bi >= 0 && bj >= 0 && bi != bj) continue;  // Cross edge.
    blocks[static_cast<std::size_t>(std::max(bi, bj))].edges.push_back(k);
  }
  for (const Block& b : blocks) out.blocks += (b.interior.empty() && b.separators.empty()) ? 0 : 1;

  std::vector<double> x = model.ToParameters(graph);
  double cost = model.Cost(x);
  out.initial_cost = cost;
  double lambda = options_.initial_lambda;
  double nu = 2.0;
  const int ds = d * num_separators;

  // Eliminates block b's interior at x with damping lambda (interior only).
  auto eliminate = [&](Block& b) {
    const int nI = d * static_cast<int>(b.interior.size());
    const int nS = d * static_cast<int>(b.separators.size());
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(b.edges.size() * static_cast<std::size_t>(4 * d * d));
    Eigen::MatrixXd HIS = Eigen::MatrixXd::Zero(nI, nS);
    Eigen::MatrixXd HSS = Eigen::MatrixXd::Zero(nS, nS);
    Eigen::VectorXd bI = Eigen::VectorXd::Zero(nI);
    Eigen::VectorXd bS = Eigen::VectorXd::Zero(nS);
    Eigen::VectorXd r;
    Eigen::MatrixXd J[2];
    for (const std::size_t k : b.edges) {
      model.Linearise(k, x, r, J[0], J[1]);
      const auto [i, j] = model.ends(k);
      const int ends[2] = {i, j};
      for (int a = 0; a < 2; ++a) {
        if (ends[a] == 0) continue;
        const VertexRole& ra = role[static_cast<std::size_t>(ends[a])];
        const Eigen::VectorXd g = -J[a].transpose() * r;
        (ra.separator ? bS.segment(d * ra.local, d) : bI.segment(d * ra.local, d)) += g;
        for (int c = 0; c < 2; ++c) {
          if (ends[c] == 0) continue;
          const VertexRole& rc = role[static_cast<std::size_t>(ends[c])];
          const Eigen::MatrixXd H = J[a].transpose() * J[c];
          if (!ra.separator && !rc.separator) {
            for (int p = 0; p < d; ++p) {
              for (int q = 0; q < d; ++q) {
                t.emplace_back(d * ra.local + p, d * rc.local + q, H(p, q));
              }
            }
          } else if (!ra.separator && rc.separator) {
            HIS.block(d * ra.local, d * rc.local, d, d) += H;
          } else if (ra.separator && rc.separator) {
            HSS.block(d * ra.local, d * rc.local, d, d) += H;
          }  // (S, I) is the transpose of (I, S).
        }
      }
    }
    b.diag_s = HSS.diagonal();
    b.b_i = bI;
    b.b_s = bS;
    if (nI == 0) {
      b.X.resize(0, nS);
      b.y.resize(0);
      b.S = std::move(HSS);
      b.c = std::move(bS);
      b.bytes = static_cast<std::size_t>(b.S.size()) * sizeof(double);
      return;
    }
    Eigen::SparseMatrix<double> HII(nI, nI);
    HII.setFromTriplets(t.begin(), t.end());
    b.damp_i.resize(nI);
    for (int p = 0; p < nI; ++p) {
      b.damp_i(p) = std::max(HII.coeff(p, p), 1e-6);
      HII.coeffRef(p, p) += lambda * b.damp_i(p);
    }
    const SparseLlt llt(HII);
    if (llt.info() != Eigen::Success) {
      b.ok = false;
      return;
    }
    b.X = llt.solve(HIS);
    b.y = llt.solve(bI);
    b.S = HSS - HIS.transpose() * b.X;
    b.c = bS - HIS.transpose() * b.y;
    b.bytes = FactorBytes(llt.matrixL().nestedExpression()) +
              static_cast<std::size_t>(HIS.size() + b.X.size() + b.S.size()) * sizeof(double);
  };

  Eigen::VectorXd r;
  Eigen::MatrixXd J[2];
  for (int it = 0; it < options_.max_iterations; ++it) {
    ++out.iterations;
    Clock::time_point t0 = Clock::now();
    ParallelFor(num_blocks, options_.num_threads,
                [&](int k) { eliminate(blocks[static_cast<std::size_t>(k)]); });
    out.eliminate_time_s += Seconds(t0);
    for (const Block& b : blocks) {
      if (!b.ok) throw GraphError(graph.source + ": Helmert blocking: singular block system");
    }

    // Reduced system: sum of the blocks' Schur complements, the edges
    // between blocks, and the damping of the separators' full diagonal.
    t0 = Clock::now();
    Eigen::VectorXd dS = Eigen::VectorXd::Zero(ds);
    Eigen::VectorXd grad_s = Eigen::VectorXd::Zero(ds);  // b_S of the full system
    Eigen::VectorXd diag = Eigen::VectorXd::Zero(ds);
    if (ds > 0) {
      std::vector<Eigen::Triplet<double>> t;
      Eigen::VectorXd rhs = Eigen::VectorXd::Zero(ds);
      for (const Block& b : blocks) {
        const int m = static_cast<int>(b.separators.size());
        for (int p = 0; p < m; ++p) {
          const int gp =
              role[static_cast<std::size_t>(b.separators[static_cast<std::size_t>(p)])].global;
          rhs.segment(d * gp, d) += b.c.segment(d * p, d);
          grad_s.segment(d * gp, d) += b.b_s.segment(d * p, d);
          diag.segment(d * gp, d) += b.diag_s.segment(d * p, d);
          for (int q = 0; q < m; ++q) {
            const int gq =
                role[static_cast<std::size_t>(b.separators[static_cast<std::size_t>(q)])].global;
            if (gq > gp) continue;  // Lower triangle only.
            for (int u = 0; u < d; ++u) {
              for (int w = 0; w < d; ++w) {
                const int row = d * gp + u;
                const int col = d * gq + w;
                if (col <= row) t.emplace_back(row, col, b.S(d * p + u, d * q + w));
              }
            }
          }
        }
      }
      for (const std::size_t k : cross_edges) {
        model.Linearise(k, x, r, J[0], J[1]);
        const auto [i, j] = model.ends(k);
        const int g[2] = {role[static_cast<std::size_t>(i)].global,
                          role[static_cast<std::size_t>(j)].global};
        for (int a = 0; a < 2; ++a) {
          rhs.segment(d * g[a], d) -= J[a].transpose() * r;
          grad_s.segment(d * g[a], d) -= J[a].transpose() * r;
          for (int c = 0; c < 2; ++c) {
            if (g[c] > g[a]) continue;
            const Eigen::MatrixXd H = J[a].transpose() * J[c];
            if (a == c) diag.segment(d * g[a], d) += H.diagonal();
            for (int u = 0; u < d; ++u) {
              for (int w = 0; w < d; ++w) {
                if (d * g[c] + w <= d * g[a] + u)
                  t.emplace_back(d * g[a] + u, d * g[c] + w, H(u, w));
              }
            }
          }
        }
      }
      for (int p = 0; p < ds; ++p) t.emplace_back(p, p, lambda * std::max(diag(p), 1e-6));
      Eigen::SparseMatrix<double> S(ds, ds);
      S.setFromTriplets(t.begin(), t.end());
      const Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>>
          llt(S);
      if (llt.info() != Eigen::Success) {
        throw GraphError(graph.source + ": Helmert blocking: singular separator system");
      }
      dS = llt.solve(rhs);
      out.separator_factor_bytes = FactorBytes(llt.matrixL().nestedExpression());
    }
    out.separator_time_s += Seconds(t0);

    // Back-substitution, then the trial point.
    t0 = Clock::now();
    std::vector<double> delta(static_cast<std::size_t>(n * d), 0.0);
    for (int v = 1; v < n; ++v) {
      const VertexRole& rv = role[static_cast<std::size_t>(v)];
      if (rv.separator) {
        for (int u = 0; u < d; ++u)
          delta[static_cast<std::size_t>(d * v + u)] = dS(d * rv.global + u);
      }
    }
    ParallelFor(num_blocks, options_.num_threads, [&](int k) {
      const Block& b = blocks[static_cast<std::size_t>(k)];
      if (b.interior.empty()) return;
      Eigen::VectorXd local(d * static_cast<int>(b.separators.size()));
      for (std::size_t p = 0; p < b.separators.size(); ++p) {
        local.segment(d * static_cast<int>(p), d) =
            dS.segment(d * role[static_cast<std::size_t>(b.separators[p])].global, d);
      }
      const Eigen::VectorXd dI = b.y - b.X * local;
      for (std::size_t p = 0; p < b.interior.size(); ++p) {
        for (int u = 0; u < d; ++u) {
          delta[static_cast<std::size_t>(d * b.interior[p] + u)] = dI(d * static_cast<int>(p) + u);
        }
      }
    });
    std::vector<double> trial = x;
    double step = 0.0;
    for (int v = 1; v < n; ++v) {
      const std::size_t s = static_cast<std::size_t>(v) * static_cast<std::size_t>(model.stride());
      model.Plus(x.data() + s, delta.data() + static_cast<std::size_t>(d * v), trial.data() + s);
    }
    double x_norm = 0.0;
    for (const double v : delta) step += v * v;
    for (const double v : x) x_norm += v * v;
    // Ceres's parameter tolerance: |dx| <= tol (|x| + tol).
    const bool small_step =
        std::sqrt(step) <= options_.step_tolerance * (std::sqrt(x_norm) + options_.step_tolerance);
    const double trial_cost = model.Cost(trial);
    // Decrease predicted by the damped linear model:
    // L(0) - L(delta) = delta^T b - delta^T H delta / 2 = (delta^T b + lambda delta^T D delta) / 2.
    double predicted = 0.0;
    for (int p = 0; p < ds; ++p) {
      predicted += dS(p) * (grad_s(p) + lambda * std::max(diag(p), 1e-6) * dS(p));
    }
    for (const Block& b : blocks) {
      for (std::size_t p = 0; p < b.interior.size(); ++p) {
        for (int u = 0; u < d; ++u) {
          const int k = d * static_cast<int>(p) + u;
          const double dv = delta[static_cast<std::size_t>(d * b.interior[p] + u)];
          predicted += dv * (b.b_i(k) + lambda * b.damp_i(k) * dv);
        }
      }
    }
    predicted *= 0.5;
    out.back_time_s += Seconds(t0);

    out.largest_block_bytes = 0;
    out.all_blocks_bytes = 0;
    for (const Block& b : blocks) {
      out.largest_block_bytes = std::max(out.largest_block_bytes, b.bytes);
      out.all_blocks_bytes += b.bytes;
    }
    // Nielsen's LM update from the gain ratio rho = actual / predicted.
    if (std::isfinite(trial_cost) && trial_cost <= cost) {
      const double decrease = cost - trial_cost;
      const double rho = predicted > 0.0 ? decrease / predicted : 1.0;
      x = std::move(trial);
      cost = trial_cost;
      lambda = std::max(lambda * std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3)), 1e-12);
      nu = 2.0;
      if (decrease <= options_.function_tolerance * cost || small_step) {
        out.converged = true;
        break;
      }
    } else {
      lambda *= nu;
      nu *= 2.0;
      if (lambda > 1e12 || small_step) {
        out.converged = small_step;
        break;
      }
    }
  }
  model.FromParameters(x, graph);
  out.final_cost = cost;
  out.time_s = Seconds(start);
  return out;
}

std::size_t FullNormalFactorBytes(const PoseGraph& graph, Objective objective) {
  const Model model(graph, objective);
  const int d = model.dim();
  const int n = static_cast<int>(graph.vertices.size());
  const std::vector<double> x = model.ToParameters(graph);
  std::vector<Eigen::Triplet<double>> t;
  Eigen::VectorXd r;
  Eigen::MatrixXd J[2];
  for (std::size_t k = 0; k < model.edges(); ++k) {
    model.Linearise(k, x, r, J[0], J[1]);
    const auto [i, j] = model.ends(k);
    const int ends[2] = {i - 1, j - 1};  // Vertex 0 fixed.
    for (int a = 0; a < 2; ++a) {
      for (int c = 0; c < 2; ++c) {
        if (ends[a] < 0 || ends[c] < 0 || ends[c] > ends[a]) continue;
        const Eigen::MatrixXd H = J[a].transpose() * J[c];
        for (int u = 0; u < d; ++u) {
          for (int w = 0; w < d; ++w) {
            if (d * ends[c] + w <= d * ends[a] + u) {
              t.emplace_back(d * ends[a] + u, d * ends[c] + w, H(u, w));
            }
          }
        }
      }
    }
  }
  const int m = d * (n - 1);
  for (int p = 0; p < m; ++p) t.emplace_back(p, p, 1e-9);
  Eigen::SparseMatrix<double> H(m, m);
  H.setFromTriplets(t.begin(), t.end());
  const SparseLlt llt(H);
  return FactorBytes(llt.matrixL().nestedExpression());
}

}  // namespace rover::mapping
