#include "msm/calibration/stiffness_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <map>
#include <numbers>

#include "meshes/foundation/errors.hpp"
#include "msm/terms/volume_term.hpp"
#include "msm/linalg/linear_solver.hpp"

namespace vessel::msm {

namespace {

/// The centreline frame at a point: radial e_ρ, circumferential e_θ, axial e_s.
std::array<Vec3, 3> centreline_frame(const VesselParams& v, const Vec3& p) {
  const CentrelineCoordinates c = centreline_coordinates(v, p);
  Vec3 axial = Vec3::UnitZ();
  if (v.kind == VesselKind::arch) {
    const double phi = std::atan2(p.y(), p.x());
    axial = Vec3(-std::sin(phi), std::cos(phi), 0.0);
  }
  Vec3 radial = c.e_rho - c.e_rho.dot(axial) * axial;
  if (radial.norm() < 1e-12) radial = axial.unitOrthogonal();
  radial.normalize();
  return {radial, axial.cross(radial), axial};
}

}  // namespace

std::vector<char> boundary_edges(const SpringNetwork& net) {
  std::map<std::array<int, 3>, int> faces;
  for (const Tet& t : net.tets) {
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> f{};
      int k = 0;
      for (int i = 0; i < 4; ++i) {
        if (i != skip) f[k++] = t[i];
      }
      std::sort(f.begin(), f.end());
      ++faces[f];
    }
  }
  std::map<std::pair<int, int>, char> on_boundary;
  for (const auto& [f, count] : faces) {
    if (count != 1) continue;
    for (int i = 0; i < 3; ++i) {
      const int a = f[i], b = f[(i + 1) % 3];
      on_boundary[{std::min(a, b), std::max(a, b)}] = 1;
    }
  }
  std::vector<char> out(net.springs.size(), 0);
  for (std::size_t s = 0; s < net.springs.size(); ++s) {
    const Spring& sp = net.springs[s];
    out[s] = on_boundary.count({std::min(sp.a, sp.b), std::max(sp.a, sp.b)}) ? 1 : 0;
  }
  return out;
}

namespace {

const char* const kDirections[3] = {"radial", "circumferential", "axial"};

/// Spring s's direction class: the largest component of its unit vector in the centreline frame
/// at its midpoint (0 radial, 1 circumferential, 2 axial).
int spring_direction(const SpringNetwork& net, const VesselParams& vessel, std::size_t s) {
  const Spring& sp = net.springs[s];
  const Vec3 a = net.nodes[static_cast<std::size_t>(sp.a)];
  const Vec3 b = net.nodes[static_cast<std::size_t>(sp.b)];
  const Vec3 d = (b - a).normalized();
  const auto frame = centreline_frame(vessel, 0.5 * (a + b));
  int best = 0;
  for (int i = 1; i < 3; ++i) {
    if (std::abs(d.dot(frame[i])) > std::abs(d.dot(frame[best]))) best = i;
  }
  return best;
}

/// Builds parameters from a class name per spring (sorted names: a stable order).
StiffnessParameters parameters_from_classes(const std::vector<std::string>& classes) {
  StiffnessParameters p;
  std::map<std::string, int> index;
  for (const std::string& c : classes) index.emplace(c, 0);
  for (auto& [name, i] : index) {
    i = static_cast<int>(p.names.size());
    p.names.push_back(name);
  }
  p.of_spring.resize(classes.size());
  for (std::size_t s = 0; s < classes.size(); ++s) p.of_spring[s] = index.at(classes[s]);
  return p;
}

}  // namespace

std::string spring_class(const SpringNetwork& net, const VesselParams& vessel,
                         const std::vector<char>& boundary_edge, std::size_t s) {
  const Spring& sp = net.springs[s];
  if (sp.family != SpringFamily::volume) return to_string(sp.family);
  return std::string("volume/") + kDirections[spring_direction(net, vessel, s)] +
         (boundary_edge[s] ? "/boundary" : "/interior");
}

double through_wall_position(const VesselParams& vessel, const Vec3& p) {
  return (centreline_coordinates(vessel, p).rho - vessel.inner_radius) / vessel.wall_thickness;
}

std::string spring_wall_layer_class(const SpringNetwork& net, const VesselParams& vessel,
                                    std::size_t s, bool edge_types) {
  const Spring& sp = net.springs[s];
  if (sp.family != SpringFamily::volume) return to_string(sp.family);
  const Vec3 a = net.nodes[static_cast<std::size_t>(sp.a)];
  const Vec3 b = net.nodes[static_cast<std::size_t>(sp.b)];
  const double xi = 0.5 * (through_wall_position(vessel, a) + through_wall_position(vessel, b));
  const char* layer = xi < 1.0 / 3.0 ? "/inner" : xi > 2.0 / 3.0 ? "/outer" : "/middle";
  if (!edge_types) {
    return std::string("volume/") + kDirections[spring_direction(net, vessel, s)] + layer;
  }
  // The frame directions the edge spans: those with |d·e_i| > kEdgeTypeComponent.
  const Vec3 d = (b - a).normalized();
  const auto frame = centreline_frame(vessel, 0.5 * (a + b));
  std::string type;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(d.dot(frame[i])) > kEdgeTypeComponent) {
      type += (type.empty() ? "" : "+") + std::string(kDirections[i]);
    }
  }
  return "volume/" + type + layer;
}

namespace {

/// κ per half of the wall by the tet's centroid ξ: "kappa/inner" ξ < 1/2, "kappa/outer".
void add_kappa_halves(StiffnessParameters& p, const SpringNetwork& net, const VesselParams& vessel) {
  const int inner = p.size();
  p.names.emplace_back("kappa/inner");
  p.names.emplace_back("kappa/outer");
  p.of_tet.resize(net.tets.size());
  for (std::size_t e = 0; e < net.tets.size(); ++e) {
    double xi = 0.0;
    for (const int n : net.tets[e]) {
      xi += 0.25 * through_wall_position(vessel, net.nodes[static_cast<std::size_t>(n)]);
    }
    p.of_tet[e] = xi < 0.5 ? inner : inner + 1;
  }
}

}  // namespace

StiffnessParameters wall_layer_parameters(const SpringNetwork& net, const VesselParams& vessel,
                                          bool with_kappa, bool edge_types) {
  std::vector<std::string> classes(net.springs.size());
  for (std::size_t s = 0; s < net.springs.size(); ++s) {
    classes[s] = spring_wall_layer_class(net, vessel, s, edge_types);
  }
  StiffnessParameters p = parameters_from_classes(classes);
  if (with_kappa && !net.tets.empty()) add_kappa_halves(p, net, vessel);
  return p;
}

StiffnessParameters group_parameters(const SpringNetwork& net, const VesselParams& vessel,
                                     bool with_kappa) {
  const std::vector<char> boundary =
      net.tets.empty() ? std::vector<char>(net.springs.size(), 0) : boundary_edges(net);
  std::vector<std::string> classes(net.springs.size());
  for (std::size_t s = 0; s < net.springs.size(); ++s) {
    classes[s] = spring_class(net, vessel, boundary, s);
  }
  StiffnessParameters p = parameters_from_classes(classes);
  if (with_kappa) {
    p.kappa = static_cast<int>(p.names.size());
    p.names.emplace_back("kappa");
  }
  return p;
}

StiffnessParameters per_section_spring_parameters(const SpringNetwork& net,
                                                  const VesselParams& vessel, bool with_kappa,
                                                  bool kappa_halves) {
  // The key of a spring's image class along the centreline: midpoint (ρ, θ) and the unit
  // vector's components in the local frame (sign fixed: the spring's ends are unordered),
  // quantised (1 nm, 1 µrad, 1e-6).
  using Key = std::array<long long, 5>;
  std::map<Key, int> index;
  std::vector<Key> keys(net.springs.size());
  for (std::size_t s = 0; s < net.springs.size(); ++s) {
    const Vec3 a = net.nodes[static_cast<std::size_t>(net.springs[s].a)];
    const Vec3 b = net.nodes[static_cast<std::size_t>(net.springs[s].b)];
    const Vec3 mid = 0.5 * (a + b);
    const CentrelineCoordinates c = centreline_coordinates(vessel, mid);
    const auto frame = centreline_frame(vessel, mid);
    Vec3 d((b - a).normalized().dot(frame[0]), (b - a).normalized().dot(frame[1]),
           (b - a).normalized().dot(frame[2]));
    for (int i = 0; i < 3; ++i) {
      if (std::abs(d[i]) > 1e-9) {
        if (d[i] < 0.0) d = -d;
        break;
      }
    }
    // θ is periodic: −π and π are the same angle.
    double theta = c.theta;
    if (theta <= -std::numbers::pi + 5e-7) theta += 2.0 * std::numbers::pi;
    keys[s] = {std::llround(c.rho * 1e9), std::llround(theta * 1e6), std::llround(d[0] * 1e6),
               std::llround(d[1] * 1e6), std::llround(d[2] * 1e6)};
    index.emplace(keys[s], 0);
  }
  StiffnessParameters p;
  for (auto& [key, i] : index) {
    i = static_cast<int>(p.names.size());
    p.names.push_back("section/" + std::to_string(i));
  }
  p.of_spring.resize(net.springs.size());
  for (std::size_t s = 0; s < net.springs.size(); ++s) p.of_spring[s] = index.at(keys[s]);
  if (with_kappa && kappa_halves && !net.tets.empty()) {
    add_kappa_halves(p, net, vessel);
  } else if (with_kappa) {
    p.kappa = static_cast<int>(p.names.size());
    p.names.emplace_back("kappa");
  }
  return p;
}

StiffnessParameters per_spring_parameters(const SpringNetwork& net, bool with_kappa,
                                          const VesselParams* kappa_halves) {
  StiffnessParameters p;
  p.names.reserve(net.springs.size() + 1);
  p.of_spring.resize(net.springs.size());
  for (std::size_t s = 0; s < net.springs.size(); ++s) {
    p.of_spring[s] = static_cast<int>(s);
    p.names.push_back("spring/" + std::to_string(s));
  }
  if (with_kappa && kappa_halves && !net.tets.empty()) {
    add_kappa_halves(p, net, *kappa_halves);
  } else if (with_kappa) {
    p.kappa = static_cast<int>(p.names.size());
    p.names.emplace_back("kappa");
  }
  return p;
}

namespace {

void check_parameters(const SpringNetwork& net, const StiffnessParameters& params,
                      const std::optional<double>& kappa, Eigen::Index theta_size) {
  if (params.of_spring.size() != net.springs.size()) {
    throw InputError("stiffness parameters: they describe " +
                     std::to_string(params.of_spring.size()) + " springs, the network has " +
                     std::to_string(net.springs.size()));
  }
  if (theta_size != params.size()) {
    throw InputError("stiffness parameters: expected " + std::to_string(params.size()) +
                     " values, got " + std::to_string(theta_size));
  }
  const auto is_kappa = [&](int p) {
    return p == params.kappa ||
           std::find(params.of_tet.begin(), params.of_tet.end(), p) != params.of_tet.end();
  };
  for (const int p : params.of_spring) {
    if (p < -1 || p >= params.size() || (p >= 0 && is_kappa(p))) {
      throw InputError("stiffness parameters: a spring names parameter " + std::to_string(p) +
                       ", expected one of the " + std::to_string(params.size()) +
                       " spring parameters");
    }
  }
  if (!params.of_tet.empty()) {
    if (params.of_tet.size() != net.tets.size() || params.kappa >= 0) {
      throw InputError("stiffness parameters: they describe the kappa of " +
                       std::to_string(params.of_tet.size()) + " tets, the network has " +
                       std::to_string(net.tets.size()));
    }
    for (const int p : params.of_tet) {
      if (p < -1 || p >= params.size()) {
        throw InputError("stiffness parameters: a tet names parameter " + std::to_string(p) +
                         ", expected one of the " + std::to_string(params.size()));
      }
    }
  }
  if (params.scales_kappa() && !kappa) {
    throw InputError("stiffness parameters: a factor for the volume term's kappa, but the model "
                     "has no volume term (expected a hybrid volume model, volume_term = true)");
  }
}

}  // namespace

void apply_stiffness_factors(SpringNetwork& net, std::optional<double>& kappa,
                             const StiffnessParameters& params, const VectorXd& theta) {
  check_parameters(net, params, kappa, theta.size());
  for (std::size_t s = 0; s < net.springs.size(); ++s) {
    const int p = params.of_spring[s];
    if (p < 0) continue;
    const double factor = std::exp(theta[p]);
    net.springs[s].law.k1 *= factor;
    net.springs[s].law.k2 *= factor;
  }
  if (params.kappa >= 0) *kappa *= std::exp(theta[params.kappa]);
  if (!params.of_tet.empty()) {
    // A κ per tet: through the per-tet factors the volume term already reads (springs.hpp).
    if (net.tet_kappa_factors.empty()) net.tet_kappa_factors.assign(net.tets.size(), 1.0);
    for (std::size_t e = 0; e < net.tets.size(); ++e) {
      const int p = params.of_tet[e];
      if (p >= 0) net.tet_kappa_factors[e] *= std::exp(theta[p]);
    }
  }
}

struct LinearisedFit::Evaluation {
  std::vector<VectorXd> u;       ///< per case, free dofs
  std::vector<VectorXd> lambda;  ///< per case, free dofs (adjoint only)
  double misfit = 0.0;
};

LinearisedFit::LinearisedFit(const SpringNetwork& net, std::optional<double> kappa,
                             const std::vector<char>& fixed, StiffnessParameters params,
                             std::vector<FitCase> cases, Regulariser regulariser)
    : params_(std::move(params)), cases_(std::move(cases)), regulariser_(regulariser) {
  check_parameters(net, params_, kappa, params_.size());
  num_dofs_ = 3 * static_cast<int>(net.nodes.size());
  if (static_cast<int>(fixed.size()) != num_dofs_) {
    throw InputError("calibration: the supports give " + std::to_string(fixed.size()) +
                     " dofs, the network has " + std::to_string(num_dofs_));
  }
  if (cases_.empty()) throw InputError("calibration: expected at least one load case to fit");
  if (regulariser_.centre.size() != 0 && regulariser_.centre.size() != params_.size()) {
    throw InputError("calibration: the regulariser's centre has " +
                     std::to_string(regulariser_.centre.size()) + " values, expected one per parameter (" +
                     std::to_string(params_.size()) + ")");
  }
  free_index_.assign(static_cast<std::size_t>(num_dofs_), -1);
  for (int i = 0; i < num_dofs_; ++i) {
    if (!fixed[static_cast<std::size_t>(i)]) free_index_[static_cast<std::size_t>(i)] = num_free_++;
  }
  for (std::size_t s = 0; s < net.springs.size(); ++s) {
    const Spring& sp = net.springs[s];
    const Vec3 d = (net.nodes[static_cast<std::size_t>(sp.b)] -
                    net.nodes[static_cast<std::size_t>(sp.a)]).normalized();
    springs_.push_back({sp.a, sp.b, params_.of_spring[s], d, sp.law.k1});
  }
  if (kappa) {
    kappa0_ = *kappa;
    for (std::size_t e = 0; e < net.tets.size(); ++e) {
      const Tet& t = net.tets[e];
      std::array<Vec3, 4> x;
      for (int i = 0; i < 4; ++i) x[i] = net.nodes[static_cast<std::size_t>(t[i])];
      // κ_e/|V₀| (the homogenised rule's per-tet κ factor, springs.hpp), as VolumeTerm.
      const double factor = net.tet_kappa_factors.empty() ? 1.0 : net.tet_kappa_factors[e];
      tets_.push_back({t, tet_volume_gradient(x), factor / std::abs(tet_signed_volume(x)),
                       params_.kappa_of_tet(e)});
    }
  }
  node_springs_.resize(net.nodes.size());
  for (std::size_t s = 0; s < springs_.size(); ++s) {
    node_springs_[static_cast<std::size_t>(springs_[s].a)].push_back(static_cast<int>(s));
    node_springs_[static_cast<std::size_t>(springs_[s].b)].push_back(static_cast<int>(s));
  }
  for (const FitCase& c : cases_) {
    if (c.force.size() != num_dofs_ || c.reference.size() != num_dofs_) {
      throw InputError("calibration case " + c.name + ": expected " + std::to_string(num_dofs_) +
                       " force and reference values (3 per node)");
    }
    const double r2 = c.reference.squaredNorm();
    if (!(r2 > 0.0) || !std::isfinite(r2)) {
      throw InputError("calibration case " + c.name +
                       ": the reference displacement is zero or not finite; expected a loaded case");
    }
    if (!(c.weight > 0.0) || !std::isfinite(c.weight)) {
      throw InputError("calibration case " + c.name + ": weight " + std::to_string(c.weight) +
                       "; expected a finite weight > 0");
    }
    weights_.push_back(c.weight / (static_cast<double>(cases_.size()) * r2));
  }
}

SparseMatrix LinearisedFit::stiffness(const VectorXd& theta) const {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(springs_.size() * 36 + tets_.size() * 144);
  const auto add = [&](int dof_i, int dof_j, double v) {
    const int i = free_index_[static_cast<std::size_t>(dof_i)];
    const int j = free_index_[static_cast<std::size_t>(dof_j)];
    if (i >= 0 && j >= 0) triplets.emplace_back(i, j, v);
  };
  for (const RestSpring& s : springs_) {
    const double k = s.param >= 0 ? s.k * std::exp(theta[s.param]) : s.k;
    const Eigen::Matrix3d block = k * s.d * s.d.transpose();
    const int nodes[2] = {s.a, s.b};
    for (int I = 0; I < 2; ++I) {
      for (int J = 0; J < 2; ++J) {
        const double sign = I == J ? 1.0 : -1.0;
        for (int r = 0; r < 3; ++r) {
          for (int c = 0; c < 3; ++c) add(3 * nodes[I] + r, 3 * nodes[J] + c, sign * block(r, c));
        }
      }
    }
  }
  if (!tets_.empty()) {
    for (const RestTet& t : tets_) {
      const double kappa = t.param >= 0 ? kappa0_ * std::exp(theta[t.param]) : kappa0_;
      const Eigen::Matrix<double, 12, 12> block = kappa * t.inv_volume * t.g * t.g.transpose();
      for (int I = 0; I < 12; ++I) {
        for (int J = 0; J < 12; ++J) {
          add(3 * t.nodes[I / 3] + I % 3, 3 * t.nodes[J / 3] + J % 3, block(I, J));
        }
      }
    }
  }
  SparseMatrix K(num_free_, num_free_);
  K.setFromTriplets(triplets.begin(), triplets.end());
  return K;
}

LinearisedFit::Evaluation LinearisedFit::evaluate(const VectorXd& theta, bool adjoint) const {
  if (theta.size() != params_.size()) {
    throw InputError("calibration: expected " + std::to_string(params_.size()) +
                     " parameters, got " + std::to_string(theta.size()));
  }
  CholmodSolver solver;
  solver.factorize(stiffness(theta));
  const auto C = static_cast<Eigen::Index>(cases_.size());
  Eigen::MatrixXd F(num_free_, C);
  for (Eigen::Index c = 0; c < C; ++c) {
    for (int i = 0; i < num_dofs_; ++i) {
      const int f = free_index_[static_cast<std::size_t>(i)];
      if (f >= 0) F(f, c) = cases_[static_cast<std::size_t>(c)].force[i];
    }
  }
  const Eigen::MatrixXd U = solver.solve_columns(F);
  Evaluation e;
  Eigen::MatrixXd R(num_free_, C);
  for (Eigen::Index c = 0; c < C; ++c) {
    const FitCase& fc = cases_[static_cast<std::size_t>(c)];
    const double w = weights_[static_cast<std::size_t>(c)];
    double sum = 0.0;
    for (int i = 0; i < num_dofs_; ++i) {
      const int f = free_index_[static_cast<std::size_t>(i)];
      const double diff = (f >= 0 ? U(f, c) : 0.0) - fc.reference[i];
      sum += diff * diff;
      if (f >= 0) R(f, c) = w * diff;
    }
    e.misfit += 0.5 * w * sum;
    e.u.emplace_back(U.col(c));
  }
  if (adjoint) {
    const Eigen::MatrixXd L = solver.solve_columns(R);  // K symmetric: Kᵀλ = K λ
    for (Eigen::Index c = 0; c < C; ++c) e.lambda.emplace_back(L.col(c));
  }
  return e;
}

double LinearisedFit::regulariser_value(const VectorXd& theta_in, VectorXd* gradient) const {
  // Both terms act on the departure from the centre, δ = θ − θ_c (Regulariser's doc); ∂δ/∂θ = 1.
  const VectorXd theta =
      regulariser_.centre.size() > 0 ? VectorXd(theta_in - regulariser_.centre) : theta_in;
  double value = 0.0;
  const double alpha = regulariser_.smoothness / std::max<double>(1.0, static_cast<double>(springs_.size()));
  if (alpha > 0.0) {
    for (const auto& incident : node_springs_) {
      if (incident.size() < 2) continue;
      double mean = 0.0;
      int counted = 0;
      for (const int s : incident) {
        const int p = springs_[static_cast<std::size_t>(s)].param;
        mean += p >= 0 ? theta[p] : 0.0;
        ++counted;
      }
      mean /= counted;
      for (const int s : incident) {
        const int p = springs_[static_cast<std::size_t>(s)].param;
        const double dev = (p >= 0 ? theta[p] : 0.0) - mean;
        value += 0.5 * alpha * dev * dev;
        // ∂/∂θ_p of ½Σ(θ_s − θ̄)² is (θ_s − θ̄) summed over p's springs (the mean's own
        // derivative multiplies Σ(θ_s − θ̄) = 0).
        if (gradient && p >= 0) (*gradient)[p] += alpha * dev;
      }
    }
  }
  const double beta = regulariser_.ridge / std::max(1, params_.size());
  if (beta > 0.0) {
    value += 0.5 * beta * theta.squaredNorm();
    if (gradient) *gradient += beta * theta;
  }
  return value;
}

double LinearisedFit::objective(const VectorXd& theta, VectorXd& gradient) const {
  gradient.setZero(params_.size());
  Evaluation e;
  try {
    e = evaluate(theta, true);
  } catch (const InputError&) {
    throw;  // bad input (sizes) stays an error
  } catch (const std::runtime_error&) {
    // K(θ) not positive definite: possible where κ is negative (the homogenised rule below
    // ν = 1/4) and a trial step scales it up. +∞ makes the line search step back.
    return std::numeric_limits<double>::infinity();
  }
  // Full-dof view of a free-dof vector's node block.
  const auto node = [&](const VectorXd& v, int n) {
    Vec3 out;
    for (int k = 0; k < 3; ++k) {
      const int f = free_index_[static_cast<std::size_t>(3 * n + k)];
      out[k] = f >= 0 ? v[f] : 0.0;
    }
    return out;
  };
  for (std::size_t c = 0; c < e.u.size(); ++c) {
    const VectorXd& u = e.u[c];
    const VectorXd& l = e.lambda[c];
    for (const RestSpring& s : springs_) {
      if (s.param < 0) continue;
      const double k = s.k * std::exp(theta[s.param]);
      const double du = s.d.dot(node(u, s.b) - node(u, s.a));
      const double dl = s.d.dot(node(l, s.b) - node(l, s.a));
      gradient[s.param] -= k * du * dl;
    }
    for (const RestTet& t : tets_) {
      if (t.param < 0) continue;
      const double kappa = kappa0_ * std::exp(theta[t.param]);
      double gu = 0.0, gl = 0.0;
      for (int i = 0; i < 4; ++i) {
        const Vec3 gi = t.g.segment<3>(3 * i);
        gu += gi.dot(node(u, t.nodes[i]));
        gl += gi.dot(node(l, t.nodes[i]));
      }
      gradient[t.param] -= kappa * t.inv_volume * gu * gl;
    }
  }
  return e.misfit + regulariser_value(theta, &gradient);
}

double LinearisedFit::misfit(const VectorXd& theta) const { return evaluate(theta, false).misfit; }

double LinearisedFit::regularisation(const VectorXd& theta) const {
  return regulariser_value(theta, nullptr);
}

std::vector<VectorXd> LinearisedFit::displacements(const VectorXd& theta) const {
  const Evaluation e = evaluate(theta, false);
  std::vector<VectorXd> out;
  for (const VectorXd& u : e.u) {
    VectorXd full = VectorXd::Zero(num_dofs_);
    for (int i = 0; i < num_dofs_; ++i) {
      const int f = free_index_[static_cast<std::size_t>(i)];
      if (f >= 0) full[i] = u[f];
    }
    out.push_back(std::move(full));
  }
  return out;
}

std::vector<double> LinearisedFit::relative_errors(const VectorXd& theta) const {
  const std::vector<VectorXd> u = displacements(theta);
  std::vector<double> out;
  for (std::size_t c = 0; c < u.size(); ++c) {
    out.push_back((u[c] - cases_[c].reference).norm() / cases_[c].reference.norm());
  }
  return out;
}

}  // namespace vessel::msm
