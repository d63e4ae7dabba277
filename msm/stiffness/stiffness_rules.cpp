#include "msm/stiffness/stiffness_rules.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <map>

#include "meshes/foundation/errors.hpp"

namespace vessel::msm {

StiffnessRule parse_stiffness_rule(const std::string& name) {
  if (name == "seed000") return StiffnessRule::seed000;
  if (name == "seed001") return StiffnessRule::seed001;
  if (name == "van-gelder" || name == "van_gelder") return StiffnessRule::van_gelder;
  if (name == "lloyd") return StiffnessRule::lloyd;
  if (name == "least-squares-fit" || name == "least_squares_fit") {
    return StiffnessRule::least_squares_fit;
  }
  if (name == "uniform") return StiffnessRule::uniform;
  throw InputError(
      "stiffness rule: expected one of seed000, seed001, van-gelder, lloyd, least-squares-fit, "
      "uniform; got '" +
      name + "'");
}

std::string to_string(StiffnessRule rule) {
  switch (rule) {
    case StiffnessRule::seed000:
      return "seed000";
    case StiffnessRule::seed001:
      return "seed001";
    case StiffnessRule::van_gelder:
      return "van-gelder";
    case StiffnessRule::lloyd:
      return "lloyd";
    case StiffnessRule::least_squares_fit:
      return "least-squares-fit";
    case StiffnessRule::uniform:
      return "uniform";
  }
  return "unknown";
}

void validate(const StiffnessParams& p) {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw InputError(what);
  };
  require(
      std::isfinite(p.youngs_modulus) && p.youngs_modulus > 0,
      "youngs_modulus E: expected a finite value > 0 Pa, got " + std::to_string(p.youngs_modulus));
  require(p.poisson_ratio >= 0.0 && p.poisson_ratio <= 0.5,
          "poisson_ratio ν: expected a value in [0, 0.5], got " + std::to_string(p.poisson_ratio));
  require(std::isfinite(p.uniform_k) && p.uniform_k > 0,
          "uniform_k: expected a finite value > 0 N/m, got " + std::to_string(p.uniform_k));
  for (double f :
       {p.structural_factor, p.shear_factor, p.bend_factor, p.two_ring_factor, p.volume_factor}) {
    require(std::isfinite(f) && f >= 0,
            "family factor: expected a finite value ≥ 0, got " + std::to_string(f));
  }
  require(
      std::isfinite(p.bilinear_ratio) && p.bilinear_ratio > 0,
      "bilinear_ratio k2/k1: expected a finite value > 0, got " + std::to_string(p.bilinear_ratio));
  require(p.bilinear_threshold_strain > 0, "bilinear_threshold_strain: expected a value > 0, got " +
                                               std::to_string(p.bilinear_threshold_strain));
}

double seed000_stiffness(double E, double area, double h0) {
  return E * area / h0;  // seed 000 eq. (4.2): k = E·A/h0
}

double seed001_stiffness(double E, double volume_around_edge, double L) {
  // seed 001 §2.2: k = E·V_T/L², V_T "the third of total volume of tetrahedrons".
  return E * (volume_around_edge / 3.0) / (L * L);
}

double van_gelder_stiffness(double E, double measure_around_edge, double L) {
  // Van Gelder (1998), abstract: k ∝ area/|c|²; k_c = E·Σ_e |T_e| / |c|² (|T_e| volume, or
  // t × area in 2D). Constant and 3D form not verified against the paper's text (see header).
  return E * measure_around_edge / (L * L);
}

double lloyd_tet_edge_stiffness(double E, double volume, double L) {
  // Lloyd et al. (2007), regular tet: k = (2√2/25)·E·l = (24/25)·E·V/l² with V = l³/(6√2);
  // per element in the V/L² form for irregular tets (header: why).
  return 24.0 / 25.0 * E * volume / (L * L);
}

double lloyd_triangle_edge_stiffness(double E, double thickness, double area, double L) {
  // Lloyd et al. (2007), equilateral triangle: k = (√3/4)·E·t = E·t·A/l² (A = (√3/4)·l²).
  return E * thickness * area / (L * L);
}

namespace {

/// Block (a, b) of an isotropic P1 element's stiffness: m·[λ ga gbᵀ + μ gb gaᵀ + μ (ga·gb) P].
void add_isotropic_blocks(Eigen::MatrixXd& K, const std::vector<Vec3>& grads, double measure,
                          double lambda, double mu, const Eigen::Matrix3d& P) {
  const int n = static_cast<int>(grads.size());
  for (int a = 0; a < n; ++a) {
    for (int b = 0; b < n; ++b) {
      const Vec3& ga = grads[a];
      const Vec3& gb = grads[b];
      K.block<3, 3>(3 * a, 3 * b) +=
          measure * (lambda * ga * gb.transpose() + mu * gb * ga.transpose() + mu * ga.dot(gb) * P);
    }
  }
}

/// Least-squares spring constants: Σ_f (g_eᵀ g_f)² k_f = g_eᵀ K g_e.
template <int NE>
std::array<double, NE> lsq_springs(const Eigen::MatrixXd& K, const std::vector<Vec3>& x,
                                   const std::array<std::pair<int, int>, NE>& edges) {
  const int n = static_cast<int>(x.size());
  std::array<Eigen::VectorXd, NE> g;
  for (int e = 0; e < NE; ++e) {
    g[e] = Eigen::VectorXd::Zero(3 * n);
    const auto [a, b] = edges[e];
    const Vec3 d = (x[a] - x[b]).normalized();
    g[e].template segment<3>(3 * a) = d;
    g[e].template segment<3>(3 * b) = -d;
  }
  Eigen::Matrix<double, NE, NE> A;
  Eigen::Matrix<double, NE, 1> rhs;
  for (int e = 0; e < NE; ++e) {
    rhs(e) = g[e].dot(K * g[e]);
    for (int f = 0; f < NE; ++f) {
      const double c = g[e].dot(g[f]);
      A(e, f) = c * c;
    }
  }
  const Eigen::Matrix<double, NE, 1> k = A.colPivHouseholderQr().solve(rhs);
  std::array<double, NE> out{};
  for (int e = 0; e < NE; ++e) out[e] = k(e);
  return out;
}

constexpr std::array<std::pair<int, int>, 6> kTetEdges{
    {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};
constexpr std::array<std::pair<int, int>, 3> kTriEdges{{{0, 1}, {0, 2}, {1, 2}}};

}  // namespace

Eigen::MatrixXd fem_tet_stiffness(const std::array<Vec3, 4>& x, double E, double nu) {
  Eigen::Matrix3d J;
  J.col(0) = x[1] - x[0];
  J.col(1) = x[2] - x[0];
  J.col(2) = x[3] - x[0];
  const double volume = std::abs(J.determinant()) / 6.0;
  const Eigen::Matrix3d Jinv = J.inverse();
  std::vector<Vec3> grads(4);
  for (int i = 0; i < 3; ++i) grads[i + 1] = Jinv.row(i).transpose();
  grads[0] = -(grads[1] + grads[2] + grads[3]);
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
  const double mu = E / (2 * (1 + nu));
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(12, 12);
  add_isotropic_blocks(K, grads, volume, lambda, mu, Eigen::Matrix3d::Identity());
  return K;
}

Eigen::MatrixXd fem_triangle_stiffness(const std::array<Vec3, 3>& x, double E, double nu,
                                       double t) {
  const Vec3 c = (x[1] - x[0]).cross(x[2] - x[0]);
  const double two_area = c.norm();
  const Vec3 n = c / two_area;
  std::vector<Vec3> grads(3);
  for (int a = 0; a < 3; ++a) {
    // ∇N_a = n × (x_c − x_b) / (2A), (a, b, c) counter-clockwise about n.
    grads[a] = n.cross(x[(a + 2) % 3] - x[(a + 1) % 3]) / two_area;
  }
  // Plane stress: λ* = Eν/(1 − ν²), μ = E/(2(1 + ν)).
  const double lambda = E * nu / (1 - nu * nu);
  const double mu = E / (2 * (1 + nu));
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - n * n.transpose();
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(9, 9);
  add_isotropic_blocks(K, grads, t * 0.5 * two_area, lambda, mu, P);
  return K;
}

std::array<double, 6> least_squares_fit_tet_stiffness(const std::array<Vec3, 4>& x, double E,
                                                      double nu) {
  return lsq_springs<6>(fem_tet_stiffness(x, E, nu), {x.begin(), x.end()}, kTetEdges);
}

std::array<double, 3> least_squares_fit_triangle_stiffness(const std::array<Vec3, 3>& x, double E,
                                                           double nu, double t) {
  return lsq_springs<3>(fem_triangle_stiffness(x, E, nu, t), {x.begin(), x.end()}, kTriEdges);
}

namespace {

using Edge = std::pair<int, int>;
Edge edge_key(int a, int b) { return a < b ? Edge{a, b} : Edge{b, a}; }

/// What a rule needs of the network and the material, refused before any spring is set.
void check_rule_inputs(const SpringNetwork& net, StiffnessRule rule, const StiffnessParams& p) {
  validate(p);
  const bool volume = !net.tets.empty();
  if (rule == StiffnessRule::least_squares_fit && volume && p.poisson_ratio >= 0.5) {
    // λ = Eν/((1+ν)(1−2ν)) is infinite at ν = 0.5: the FEM element matrix to fit does not exist.
    throw InputError(
        "stiffness rule least-squares-fit on tetrahedra: poisson_ratio ν = 0.5 makes λ infinite; "
        "expected ν < 0.5");
  }
  if (!volume && rule != StiffnessRule::uniform && !(net.thickness > 0)) {
    throw InputError("assign_stiffness: a surface network needs a wall thickness t > 0");
  }
}

/// Per element edge: the element measure around it (Σ V, or t·Σ A) and, for the
/// least-squares-fit rule, the sum of the elements' fitted stiffnesses.
struct EdgeMeasures {
  std::map<Edge, double> measure, fitted;
};

EdgeMeasures edge_measures(const SpringNetwork& net, bool fit, const StiffnessParams& p) {
  EdgeMeasures out;
  const double E = p.youngs_modulus, t = net.thickness;
  if (!net.tets.empty()) {
    for (const Tet& tet : net.tets) {
      std::array<Vec3, 4> x{net.nodes[tet[0]], net.nodes[tet[1]], net.nodes[tet[2]],
                            net.nodes[tet[3]]};
      const double V = std::abs(signed_volume(x[0], x[1], x[2], x[3]));
      std::array<double, 6> kl{};
      if (fit) kl = least_squares_fit_tet_stiffness(x, E, p.poisson_ratio);
      for (int e = 0; e < 6; ++e) {
        const Edge k = edge_key(tet[kTetEdges[e].first], tet[kTetEdges[e].second]);
        out.measure[k] += V;
        out.fitted[k] += kl[e];
      }
    }
  } else {
    for (const Triangle& tri : net.triangles) {
      std::array<Vec3, 3> x{net.nodes[tri[0]], net.nodes[tri[1]], net.nodes[tri[2]]};
      const double A = triangle_area(x[0], x[1], x[2]);
      std::array<double, 3> kl{};
      if (fit) kl = least_squares_fit_triangle_stiffness(x, E, p.poisson_ratio, t);
      for (int e = 0; e < 3; ++e) {
        const Edge k = edge_key(tri[kTriEdges[e].first], tri[kTriEdges[e].second]);
        out.measure[k] += t * A;
        out.fitted[k] += kl[e];
      }
    }
  }
  return out;
}

/// The rule's stiffness of one spring of rest length L: `is_edge` when it lies on an element
/// edge (measure m around it, fitted its least-squares sum), else m is its surrogate measure.
double rule_stiffness(StiffnessRule rule, const StiffnessParams& p, bool volume, double t,
                      double L, bool is_edge, double m, double fitted) {
  const double E = p.youngs_modulus;
  switch (rule) {
    case StiffnessRule::seed000:
      return seed000_stiffness(E, volume ? L * L : t * L, L);
    case StiffnessRule::seed001:
      return seed001_stiffness(E, m, L);
    case StiffnessRule::van_gelder:
      return van_gelder_stiffness(E, m, L);
    case StiffnessRule::lloyd:
      // Σ over the elements sharing the edge of the per-element closed form; a non-edge spring
      // takes the equilateral triangle's (√3/4)·E·t, as van_gelder.
      if (!is_edge) return van_gelder_stiffness(E, m, L);
      if (volume) return lloyd_tet_edge_stiffness(E, m, L);  // (24/25)·E·Σ V_e/L²
      return lloyd_triangle_edge_stiffness(E, 1.0, m, L);     // m = t·Σ A_e already
    case StiffnessRule::least_squares_fit:
      return is_edge ? fitted : van_gelder_stiffness(E, m, L);
    case StiffnessRule::uniform:
      return p.uniform_k;
  }
  return 0.0;
}

/// The calibration factor of a spring family.
double family_factor(SpringFamily family, const StiffnessParams& p) {
  switch (family) {
    case SpringFamily::structural:
      return p.structural_factor;
    case SpringFamily::shear:
      return p.shear_factor;
    case SpringFamily::bend:
      return p.bend_factor;
    case SpringFamily::two_ring:
      return p.two_ring_factor;
    case SpringFamily::volume:
      return p.volume_factor;
  }
  return 1.0;
}

}  // namespace

void assign_stiffness(SpringNetwork& net, StiffnessRule rule, const StiffnessParams& p) {
  check_rule_inputs(net, rule, p);
  const bool volume = !net.tets.empty();
  const double t = net.thickness;
  const EdgeMeasures edges = edge_measures(net, rule == StiffnessRule::least_squares_fit, p);
  for (Spring& s : net.springs) {
    const double L = s.rest_length;
    if (rule != StiffnessRule::uniform && !(L > 0.0)) {
      // Every rule but the uniform one divides by the rest length (k ∝ 1/L or 1/L²).
      throw InputError("stiffness rule " + to_string(rule) + ": the spring between nodes " +
                       std::to_string(s.a) + " and " + std::to_string(s.b) +
                       " has zero rest length (coincident nodes); expected distinct nodes");
    }
    const Edge key = edge_key(s.a, s.b);
    const auto it = edges.measure.find(key);
    // Only structural and volume springs take their element measure: a shear spring on a grid
    // cell may or may not coincide with the diagonal the mesher cut the cell along, and both
    // diagonals must be treated alike.
    const bool is_edge = it != edges.measure.end() &&
                         (s.family == SpringFamily::structural || s.family == SpringFamily::volume);
    // Surrogate measure of a non-edge spring: one equilateral triangle on it (see header).
    const double m = is_edge ? it->second : t * std::sqrt(3.0) / 4.0 * L * L;
    const double k = rule_stiffness(rule, p, volume, t, L, is_edge, m,
                                    is_edge ? edges.fitted.at(key) : 0.0);
    s.law.k1 = family_factor(s.family, p) * k;
    s.law.k2 = p.bilinear_ratio * s.law.k1;
    s.law.threshold = p.bilinear_threshold_strain * L;  // infinite → Hooke
  }
}

}  // namespace vessel::msm
