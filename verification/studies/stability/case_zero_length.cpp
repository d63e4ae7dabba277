// Hard case: springs with zero rest length, coincident nodes.
#include "verification/studies/stability/study_models.hpp"

#include <cmath>
#include <limits>

#include "meshes/foundation/errors.hpp"
#include "meshes/mesh_quality.hpp"
#include "msm/solvers/critical_step.hpp"
#include "msm/stability/stability_search.hpp"

namespace vessel::stability_study {

namespace {

/// The network plus one node coincident with node j, tied to it by a zero-rest-length spring
/// of the network's mean stiffness.
msm::SpringNetwork with_zero_length_spring(msm::SpringNetwork net, int j) {
  double kmean = 0.0;
  for (const auto& sp : net.springs) kmean += sp.law.k1;
  kmean /= static_cast<double>(net.springs.size());
  net.nodes.push_back(net.nodes[j]);
  net.source_node.push_back(-1);
  msm::Spring z;
  z.a = j;
  z.b = static_cast<int>(net.nodes.size()) - 1;
  z.rest_length = 0.0;
  z.law = {kmean, kmean};
  net.springs.push_back(z);
  return net;
}

/// The problem with the extra (last) node of `net`: at its rest position, node j's mass, no
/// load, free.
msm::Problem with_extra_node(msm::Problem p, const msm::SpringNetwork& net, int j) {
  const Eigen::Index n = p.rest.size();
  p.rest.conservativeResize(n + 3);
  p.rest.tail<3>() = net.nodes.back();
  p.mass.conservativeResize(n + 3);
  p.mass.tail<3>().setConstant(p.mass[3 * j]);
  p.external_force.conservativeResize(n + 3);
  p.external_force.tail<3>().setZero();
  p.fixed.resize(static_cast<std::size_t>(n + 3), 0);
  return p;
}

/// (1) The volume model plus a zero-length spring at the contact node: its spectrum, a static
/// solve and symplectic Euler at half the model's predicted critical step.
void add_zero_length_outcomes(HardCase& hc, const Scene& scene, const TetMesh& mesh,
                              const ModelSpec& spec) {
  auto m = build_model(scene, mesh, spec, 0.25);
  const int j = static_cast<int>(m->contact_node);
  const msm::SpringNetwork net = with_zero_length_spring(m->built.network, j);
  const auto model = msm::make_model(net);
  msm::Problem p = with_extra_node(m->problem, net, j);
  p.form = model.get();
  HardCaseOutcome sp;
  sp.model = "volume / seed001 + zero-length spring: spectrum";
  try {
    const msm::Spectrum s = msm::analyse_spectrum(p);
    sp.finished = true;
    // ½kL² has the Hessian k[I −I; −I I] at zero length; a kernel that returned zero there
    // would leave the extra node without stiffness (ω_min = 0).
    sp.reported = "ω_max " + fmt(s.omega_max) + " rad/s, ω_min " + fmt(s.omega_min) + " rad/s" +
                  (s.omega_min > 0.0 ? " (the zero-length spring's Hessian k[I −I; −I I] holds "
                                       "the extra node)"
                                     : " (0: the extra node has no stiffness at rest)");
    sp.values["omega_min"] = s.omega_min;
  } catch (const std::exception& e) {
    sp.reported = "failed: " + short_error(e.what());
  }
  hc.outcomes.push_back(sp);
  StudyModel tmp;
  tmp.problem = p;
  tmp.contact_node = m->contact_node;
  tmp.model = msm::make_model(net);
  tmp.problem.form = tmp.model.get();
  hc.outcomes.push_back(static_outcome("volume / seed001 + zero-length spring: static", tmp));
  const double dt = 0.5 * msm::predicted_critical_step(
                              Integrator::symplectic_euler,
                              msm::analyse_spectrum(m->problem, {.lowest = false}));
  hc.outcomes.push_back(dynamic_outcome("volume / seed001 + zero-length spring: symplectic Euler",
                                        tmp.problem, Integrator::symplectic_euler, dt, 2000));
}

/// The mesh with coincident nodes: in the tet nearest `point`, the first node moved onto the
/// second.
TetMesh with_coincident_nodes(const TetMesh& mesh, const Vec3& point) {
  int a = -1, b = -1;
  double best = std::numeric_limits<double>::infinity();
  for (const Tet& t : mesh.tets) {
    const double d = (mesh.nodes[t[0]] - point).squaredNorm();
    if (d < best) {
      best = d;
      a = t[0];
      b = t[1];
    }
  }
  TetMesh bad = mesh;
  if (a >= 0) bad.nodes[a] = bad.nodes[b];
  return bad;
}

/// (2) The mesh with coincident nodes: its quality, the reader's volume check, the volume
/// models of two stiffness rules and the FEM on it.
void add_coincident_outcomes(HardCase& hc, const Scene& scene, const TetMesh& bad) {
  const MeshQuality q = compute_quality(bad);
  hc.outcomes.push_back({"mesh quality", true, {}, {},
                         std::to_string(q.degenerate) + " zero-volume and " +
                             std::to_string(q.inverted) + " inverted tets reported",
                         {{"degenerate_tets", static_cast<double>(q.degenerate)}}});
  // The same mesh as a user's .msh file: the reader's volume check (require_positive_volumes)
  // refuses it before any model sees it. The rows below show what happens without that check.
  try {
    require_positive_volumes(bad, "coincident-node mesh");
    hc.outcomes.push_back({"reading it as a user .msh", true, {}, {}, "accepted", {}});
  } catch (const InputError& e) {
    hc.outcomes.push_back({"reading it as a user .msh", false, {}, {},
                           "refused: " + short_error(e.what()), {}});
  }
  for (msm::StiffnessRule rule : {msm::StiffnessRule::seed001, msm::StiffnessRule::van_gelder}) {
    const ModelSpec sp = volume_model(rule);
    try {
      const auto m = build_model(scene, bad, sp, 0.25);
      std::size_t bad_k = 0;
      for (const auto& s : m->built.network.springs) {
        if (!std::isfinite(s.law.k1)) ++bad_k;
      }
      HardCaseOutcome oc = static_outcome(sp.name + ", coincident nodes", *m);
      oc.reported = std::to_string(bad_k) + " springs with non-finite k; " + oc.reported;
      hc.outcomes.push_back(oc);
    } catch (const std::exception& e) {
      hc.outcomes.push_back({sp.name + ", coincident nodes", false, false, {},
                             "refused: " + short_error(e.what()), {}});
    }
  }
  hc.outcomes.push_back(fem_outcome(
      "FEM P1, coincident nodes",
      run_fem(scene, bad, 0.3, 1, fem::Formulation::displacement)));
}

}  // namespace

HardCase case_zero_length(const StabilityOptions& o, std::ostream& log) {
  HardCase hc;
  hc.id = "zero_length";
  hc.title = "Springs with zero rest length, coincident nodes";
  hc.setup = "(1) The level-0 volume model (seed001) plus one extra node coincident with a free "
             "node near the contact point, tied to it by a zero-rest-length spring of the mean "
             "stiffness; (2) the level-0 mesh with one interior node moved onto a neighbour "
             "(coincident nodes, zero-volume tets): a .msh file like it is refused by the "
             "reader (inverted or zero-volume tets, exit 1); the models are run on it here "
             "anyway to show why. Contact load 0.1 mN, clamped ends.";
  const Scene scene = study_scene(VesselParams{}, 14.24e3, 1e-4);
  const TetMesh mesh = case_mesh(scene, o);
  const Vec3 point = qoi_point(scene);
  const ModelSpec spec = volume_model(msm::StiffnessRule::seed001);
  log << "  zero-length spring" << std::endl;
  add_zero_length_outcomes(hc, scene, mesh, spec);
  log << "  coincident nodes" << std::endl;
  add_coincident_outcomes(hc, scene, with_coincident_nodes(mesh, point));
  return hc;
}

}  // namespace vessel::stability_study
