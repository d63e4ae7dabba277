/// The serial FEM transient of a step load: Newmark average acceleration on the displacement
/// system's unconstrained DoFs, K + (4/dt² + 2α/dt) M factorised once by CHOLMOD.
#include <cmath>
#include <sstream>

#include "fem_reference/cholmod_solve.hpp"
#include "fem_reference/detail/serial_solver.hpp"
#include "meshes/foundation/errors.hpp"

namespace vessel::fem {

using SpMat = Eigen::SparseMatrix<double>;

namespace {

/// InputError for what the transient cannot do: the mixed system, dt ≤ 0, steps ≤ 0, α < 0,
/// density ≤ 0.
void check_transient(const TransientOptions& o, bool mixed, double density) {
  if (mixed) {
    throw InputError(
        "FEM transient needs the displacement formulation (P1 or P2); the mixed Taylor-Hood "
        "system is not supported: use --formulation displacement or nu below the mixed "
        "threshold");
  }
  std::ostringstream bad;
  if (!std::isfinite(o.dt) || o.dt <= 0.0) {
    bad << "transient time step dt = " << o.dt << " s is invalid: expected dt > 0";
  } else if (o.steps <= 0) {
    bad << "transient steps = " << o.steps << " is invalid: expected steps > 0";
  } else if (!std::isfinite(o.mass_damping) || o.mass_damping < 0.0) {
    bad << "transient mass damping alpha = " << o.mass_damping
        << " 1/s is invalid: expected alpha >= 0";
  } else if (!(density > 0.0)) {
    bad << "FEM transient needs density > 0 (the mass matrix); found " << density << " kg/m^3";
  }
  if (!bad.str().empty()) throw InputError(bad.str());
}

}  // namespace

TransientResult ElasticitySolver::transient(const TransientOptions& o) const {
  const auto& im = *impl_;
  check_transient(o, im.mixed, im.problem.material.density);
  // Probes first, so that a bad point fails before the expensive part.
  std::vector<Impl::PointStencil> probes;
  for (const auto& x : o.probe_points) probes.push_back(im.point_stencil(x, o.outside_tolerance));

  const auto t0 = detail::Clock::now();
  const auto sys = im.assemble_free_system(true);
  const SpMat& K = sys.K;
  const SpMat& M = sys.M;
  const Eigen::VectorXd& f = sys.f;
  const double dt = o.dt, alpha = o.mass_damping;
  // Newmark, β = 1/4, γ = 1/2 (Newmark 1959; Hughes, The Finite Element Method, 2000, §9.1):
  //   u₁ = u₀ + dt v₀ + dt²/4 (a₀ + a₁),  v₁ = v₀ + dt/2 (a₀ + a₁),  M a + C v + K u = f,
  // so (K + 4/dt² M + 2/dt C) u₁ = f + M(4/dt² u₀ + 4/dt v₀ + a₀) + C(2/dt u₀ + v₀). With C = αM
  // and M a₀ = f − K u₀ − C v₀ (equilibrium at the previous step; no solve with M needed).
  const double cu = 4.0 / (dt * dt) + 2.0 * alpha / dt;
  const double cv = 4.0 / dt + alpha;
  const SpMat Keff = K + cu * M;
  const CholmodFactor factor(Keff);
  TransientResult r;
  r.setup_seconds = detail::seconds_since(t0);
  r.n_dofs = im.dof.n_dofs();

  const Eigen::Index n = K.rows();
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n), v = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd Ma = f;  // M a₀ = f (at rest)
  auto value_of = [&](Index d) {
    const int fi = sys.free_index[d];
    return fi < 0 ? sys.constrained_value[d] : u[fi];
  };
  auto record = [&](double t, const Eigen::VectorXd& Ku, const Eigen::VectorXd& Mv) {
    r.time.push_back(t);
    std::vector<Vec3> at(probes.size(), Vec3::Zero());
    for (std::size_t p = 0; p < probes.size(); ++p) {
      for (std::size_t i = 0; i < probes[p].dofs.size(); ++i)
        at[p][probes[p].components[i]] += value_of(probes[p].dofs[i]) * probes[p].weights[i];
    }
    r.probe_displacement.push_back(std::move(at));
    r.kinetic_energy.push_back(0.5 * v.dot(Mv));
    r.strain_energy.push_back(0.5 * u.dot(Ku));
    r.load_work.push_back(f.dot(u));
  };
  r.time.reserve(static_cast<std::size_t>(o.steps) + 1);
  record(0.0, Eigen::VectorXd::Zero(n), Eigen::VectorXd::Zero(n));
  const auto t1 = detail::Clock::now();
  for (int step = 1; step <= o.steps; ++step) {
    const Eigen::VectorXd rhs = f + Ma + M * (cu * u + cv * v);
    Eigen::VectorXd u1 = factor.solve(rhs);
    v = (2.0 / dt) * (u1 - u) - v;  // v₁ = 2/dt (u₁ − u₀) − v₀ (γ = 1/2)
    u = std::move(u1);
    const Eigen::VectorXd Ku = K * u;
    const Eigen::VectorXd Mv = M * v;
    Ma = f - Ku - alpha * Mv;
    if (!u.allFinite()) {
      throw std::runtime_error("FEM transient: non-finite displacement at step " +
                               std::to_string(step));
    }
    record(step * dt, Ku, Mv);
  }
  r.seconds_per_step = detail::seconds_since(t1) / o.steps;

  r.final_nodal_displacement = im.nodal(value_of);
  return r;
}

}  // namespace vessel::fem
