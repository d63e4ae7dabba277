#include "msm/terms/volume_term_homogenised.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "meshes/foundation/errors.hpp"
#include "msm/terms/spring_model.hpp"
#include "msm/terms/volume_term.hpp"
#include "msm/linalg/linear_solver.hpp"
#include "msm/stiffness/stiffness_rules.hpp"
#include "msm/topology/springs.hpp"

namespace vessel::msm {

namespace {

std::string num(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", x);
  return b;
}

/// A statically determinate support against the six rigid motions (3-2-1): every dof of node a,
/// two components of node b (the node farthest from a) and one of node c (farthest from the line
/// ab), the components chosen so that the three rows acting on a rotation ω (u = ω × (x − x_a))
/// have the largest determinant. An equilibrated load then leaves no reaction.
std::vector<char> rigid_support(const std::vector<Vec3>& nodes) {
  const int n = static_cast<int>(nodes.size());
  const int a = 0;
  int b = a;
  for (int i = 0; i < n; ++i) {
    if ((nodes[i] - nodes[a]).squaredNorm() > (nodes[b] - nodes[a]).squaredNorm()) b = i;
  }
  const Vec3 ab = nodes[b] - nodes[a];
  int c = a;
  double best = 0.0;
  for (int i = 0; i < n; ++i) {
    const double d = ab.cross(nodes[i] - nodes[a]).squaredNorm();
    if (d > best) best = d, c = i;
  }
  if (!(best > 1e-24 * ab.squaredNorm() * ab.squaredNorm()) || b == a) {
    throw InputError(
        "homogenised volume model: the mesh's nodes are collinear; expected a 3-D "
        "tetrahedral mesh");
  }
  // Row k of u_p = ω × r is −([r]×)_k · ω... written as (r × e_k)·ω.
  auto row = [](const Vec3& r, int k) { return Vec3(r.cross(Vec3::Unit(k))); };
  const Vec3 ac = nodes[c] - nodes[a];
  double best_det = -1.0;
  int bi = 0, bj = 1, ck = 0;
  for (int i = 0; i < 3; ++i) {
    for (int j = i + 1; j < 3; ++j) {
      for (int k = 0; k < 3; ++k) {
        Eigen::Matrix3d m;
        m.row(0) = row(ab, i);
        m.row(1) = row(ab, j);
        m.row(2) = row(ac, k);
        const double d = std::abs(m.determinant());
        if (d > best_det) best_det = d, bi = i, bj = j, ck = k;
      }
    }
  }
  std::vector<char> fixed(3 * nodes.size(), 0);
  for (int k = 0; k < 3; ++k) fixed[3 * a + k] = 1;
  fixed[3 * b + bi] = 1;
  fixed[3 * b + bj] = 1;
  fixed[3 * c + ck] = 1;
  return fixed;
}

/// The rows/columns of the free dofs of a symmetric matrix.
SparseMatrix restrict_to(const SparseMatrix& A, const std::vector<int>& free_index, int num_free) {
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(A.nonZeros());
  for (int col = 0; col < A.outerSize(); ++col) {
    const int fc = free_index[col];
    if (fc < 0) continue;
    for (SparseMatrix::InnerIterator it(A, col); it; ++it) {
      const int fr = free_index[it.row()];
      if (fr >= 0) t.emplace_back(fr, fc, it.value());
    }
  }
  SparseMatrix R(num_free, num_free);
  R.setFromTriplets(t.begin(), t.end());
  return R;
}

}  // namespace

TractionHomogenisation::TractionHomogenisation(const std::vector<Vec3>& nodes,
                                               const std::vector<Tet>& tets) {
  if (nodes.size() < 4 || tets.empty()) {
    throw InputError("homogenised volume model: expected a tetrahedral mesh, got " +
                     std::to_string(nodes.size()) + " nodes and " + std::to_string(tets.size()) +
                     " tets");
  }
  num_dofs_ = 3 * static_cast<int>(nodes.size());
  TetMesh mesh;
  mesh.nodes = nodes;
  mesh.tets = tets;
  SpringNetwork net = build_volume_network(mesh);
  StiffnessParams unit;
  unit.youngs_modulus = 1.0;
  assign_stiffness(net, StiffnessRule::van_gelder, unit);
  const VectorXd rest = flatten(nodes);
  SparseMatrix K1;
  SpringModel(net, 0.0).hessian(rest, K1, false);
  const VolumeTerm volume(nodes, tets, 1.0);  // InputError for a degenerate tet
  for (double v0 : volume.rest_volumes()) volume_ += std::abs(v0);
  nodes_ = nodes;
  tets_ = tets;

  const std::vector<char> fixed = rigid_support(nodes);
  std::vector<int>& free_index = free_index_;
  free_index.assign(num_dofs_, -1);
  int& num_free = num_free_;
  for (int d = 0; d < num_dofs_; ++d) {
    if (!fixed[d]) free_index[d] = num_free++;
  }
  springs_ = restrict_to(K1, free_index, num_free);

  // ε̄ = (1/V)·Σ_faces Σ_corners sym(u_i ⊗ m), m = (area vector)/3: the boundary integral of
  // sym(u ⊗ n) for the piecewise-linear u (divergence theorem, exact).
  strain_ = Eigen::MatrixXd::Zero(6, num_free);
  const double s2 = std::sqrt(0.5);
  for (const Triangle& f : boundary_faces(mesh)) {
    const Vec3 m = (nodes[f[1]] - nodes[f[0]]).cross(nodes[f[2]] - nodes[f[0]]) / 6.0 / volume_;
    for (int node : f) {
      auto add = [&](int row, int comp, double value) {
        const int col = free_index[3 * node + comp];
        if (col >= 0) strain_(row, col) += value;
      };
      for (int k = 0; k < 3; ++k) add(k, k, m[k]);  // ε_kk = u_k m_k
      // √2·ε_ij = (u_i m_j + u_j m_i)/√2 for (23), (13), (12).
      add(3, 1, s2 * m[2]), add(3, 2, s2 * m[1]);
      add(4, 0, s2 * m[2]), add(4, 2, s2 * m[0]);
      add(5, 0, s2 * m[1]), add(5, 1, s2 * m[0]);
    }
  }
  // Virtual work of the traction σ·n: f·u = ∫ σn·u dA = V·σ_M·ε̄_M(u), so the consistent nodal
  // loads of the six unit Mandel stresses are the columns of V·strainᵀ (free dofs; the support's
  // dofs carry no reaction since the load is equilibrated).
  loads_ = volume_ * strain_.transpose();
}

std::optional<TractionModuli> TractionHomogenisation::moduli(
    double spring_youngs_modulus, double kappa, const std::vector<double>& tet_factors) const {
  SparseMatrix KV;
  VolumeTerm(nodes_, tets_, kappa, tet_factors).hessian(flatten(nodes_), KV, false);
  const SparseMatrix K = spring_youngs_modulus * springs_ + restrict_to(KV, free_index_, num_free_);
  CholmodSolver solver;
  if (!solver.try_factorize(K)) return std::nullopt;
  TractionModuli m;
  m.compliance = strain_ * solver.solve_columns(loads_);
  m.compliance = 0.5 * (m.compliance + m.compliance.transpose()).eval();  // symmetric to round-off
  // Isotropic projection (Frobenius, Mandel): J = (1/3)·1⊗1, the rest is deviatoric (rank 5).
  const double a = m.compliance.topLeftCorner<3, 3>().sum() / 3.0;  // 1/(3K)
  const double b = (m.compliance.trace() - a) / 5.0;                // 1/(2μ)
  m.bulk_modulus = 1.0 / (3.0 * a);
  m.shear_modulus = 1.0 / (2.0 * b);
  const double K3 = 3.0 * m.bulk_modulus, mu = m.shear_modulus;
  m.isotropic_youngs_modulus = 3.0 * K3 * mu / (K3 + mu);
  m.isotropic_poisson_ratio = (K3 - 2.0 * mu) / (2.0 * (K3 + mu));
  // Uniaxial stress along each axis, averaged.
  const auto& S = m.compliance;
  m.youngs_modulus = 3.0 / (S(0, 0) + S(1, 1) + S(2, 2));
  m.poisson_ratio = -m.youngs_modulus * (S(0, 1) + S(0, 2) + S(1, 2)) / 3.0;
  return m;
}

double volume_stability_limit(const std::array<Vec3, 4>& x) {
  Eigen::Matrix<double, 6, 6> G = Eigen::Matrix<double, 6, 6>::Zero();
  const double s2 = std::sqrt(2.0);
  for (int i = 0; i < 4; ++i) {
    for (int j = i + 1; j < 4; ++j) {
      const Vec3 d = (x[j] - x[i]).normalized();
      Eigen::Matrix<double, 6, 1> w;
      w << d.x() * d.x(), d.y() * d.y(), d.z() * d.z(), s2 * d.y() * d.z(), s2 * d.x() * d.z(),
          s2 * d.x() * d.y();
      G += w * w.transpose();
    }
  }
  Eigen::Matrix<double, 6, 1> m;
  m << 1, 1, 1, 0, 0, 0;
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(G);
  const double q = m.dot(ldlt.solve(m));
  if (ldlt.info() != Eigen::Success || !(q > 0) || !std::isfinite(q)) {
    throw InputError(
        "homogenised volume model: a degenerate tetrahedron (its six edges do not "
        "determine its strain)");
  }
  return -1.0 / q;
}

std::vector<double> stability_clipped_factors(const std::vector<Vec3>& nodes,
                                              const std::vector<Tet>& tets, double r) {
  if (r >= 0.0) return {};
  std::vector<double> f;
  f.reserve(tets.size());
  for (const Tet& t : tets) {
    const double c = volume_stability_limit({nodes[t[0]], nodes[t[1]], nodes[t[2]], nodes[t[3]]});
    f.push_back(std::max(r, kStabilityMargin * c) / r);
  }
  return f;
}

std::string homogenised_refusal(double E, double nu) {
  if (!(E > 0) || !std::isfinite(E)) {
    return "homogenised volume model: expected Young's modulus E > 0 Pa, got " + num(E);
  }
  if (!(nu >= 0.0 && nu < 0.5)) {
    return "homogenised volume model (volume_moduli = \"homogenised\"): poisson_ratio ν must be in "
           "[0, 0.5), got " +
           num(nu) +
           (nu >= 0.5 ? "; at ν = 0.5 the volume term's κ is infinite (an incompressibility "
                        "constraint, which this penalty model does not offer)"
                      : "");
  }
  return {};
}

HomogenisedModuli homogenised_moduli(const std::vector<Vec3>& nodes, const std::vector<Tet>& tets,
                                     double E, double nu) {
  if (std::string why = homogenised_refusal(E, nu); !why.empty()) throw InputError(why);
  const TractionHomogenisation h(nodes, tets);
  HomogenisedModuli out;
  // Golec's rule on the same network, for comparison.
  {
    const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
    const auto g = h.moduli(2.5 * mu, lambda - mu);
    ++out.evaluations;
    out.golec_youngs_modulus = g ? g->youngs_modulus : std::nan("");
    out.golec_poisson_ratio = g ? g->poisson_ratio : std::nan("");
  }
  // r = κ/E_s through the nominal ν_n of the affine estimate (msm/stiffness/hybrid_moduli.hpp), x = ν_n.
  auto ratio = [](double x) { return (1.6 * x - 0.4) / (1.0 - 2.0 * x); };
  struct Point {
    double x, f;
    TractionModuli m;
  };
  auto evaluate = [&](double x) {
    const double r = ratio(x);
    const auto m = h.moduli(1.0, r, stability_clipped_factors(nodes, tets, r));
    ++out.evaluations;
    if (!m) {  // the clip makes every tet's block positive definite: not expected
      throw InputError(
          "homogenised volume model: the network's stiffness is not positive "
          "definite at κ/E_s = " +
          num(r) + "; expected a connected tet mesh");
    }
    return Point{x, m->poisson_ratio - nu, *m};
  };
  constexpr double kTolerance = 1e-6;
  // Below r_floor = margin·min_e c_e every tet is clipped: ν_eff stops falling there.
  double r_floor = 0.0;
  for (const Tet& t : tets) {
    r_floor = std::min(
        r_floor, kStabilityMargin *
                     volume_stability_limit({nodes[t[0]], nodes[t[1]], nodes[t[2]], nodes[t[3]]}));
  }
  double lo = (r_floor + 0.4) / (1.6 + 2.0 * r_floor), hi = 0.5;  // f(lo) ≤ 0 < f(hi)
  std::optional<Point> found, previous;
  if (nu < 0.25) {
    const Point floor = evaluate(lo);
    if (std::abs(floor.f) < kTolerance) found = floor;
    if (floor.f > 0) {
      throw InputError("homogenised volume model: poisson_ratio ν = " + num(nu) +
                       " is below the lowest effective ν this mesh's network reaches (" +
                       num(floor.m.poisson_ratio) + ": every tet's negative κ at " +
                       num(kStabilityMargin) +
                       " of its own stability limit, volume_term_homogenised.hpp); expected ν ≥ " +
                       num(std::ceil(floor.m.poisson_ratio * 1000) / 1000));
    }
    previous = floor;
  }
  double x = nu;
  for (int it = 0; it < 60 && !found; ++it) {
    const Point p = evaluate(x);
    if (std::abs(p.f) < kTolerance) {
      found = p;
      break;
    }
    (p.f < 0 ? lo : hi) = x;
    double next = previous && previous->f != p.f ? x - p.f * (x - previous->x) / (p.f - previous->f)
                                                 : x - p.f;  // ν_eff ≈ ν_n − offset: unit slope
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    previous = p;
    x = next;
  }
  if (!found) {
    throw InputError("homogenised volume model: the fit of κ/E_s to ν = " + num(nu) +
                     " did not converge (" + std::to_string(out.evaluations) + " homogenisations)");
  }
  const double r = ratio(found->x);
  out.spring_youngs_modulus = E / found->m.youngs_modulus;
  out.kappa = r * out.spring_youngs_modulus;
  out.tet_factors = stability_clipped_factors(nodes, tets, r);
  std::size_t clipped = 0;
  for (double f : out.tet_factors) clipped += f < 1.0 ? 1 : 0;
  out.clipped_fraction = static_cast<double>(clipped) / static_cast<double>(tets.size());
  // The compliance is homogeneous of degree −1 in (E_s, κ): scale, no further solve.
  out.achieved = found->m;
  out.achieved.youngs_modulus *= out.spring_youngs_modulus;
  out.achieved.bulk_modulus *= out.spring_youngs_modulus;
  out.achieved.shear_modulus *= out.spring_youngs_modulus;
  out.achieved.isotropic_youngs_modulus *= out.spring_youngs_modulus;
  out.achieved.compliance /= out.spring_youngs_modulus;
  return out;
}

}  // namespace vessel::msm
