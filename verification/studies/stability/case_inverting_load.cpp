// Hard case: a large load that inverts elements.
#include "verification/studies/stability/study_models.hpp"

#include "msm/solvers/critical_step.hpp"
#include "msm/stability/stability_search.hpp"

namespace vessel::stability_study {

HardCase case_inverting_load(const StabilityOptions& o, std::ostream& log) {
  HardCase hc;
  hc.id = "inverting_load";
  hc.title = "A large load that inverts elements";
  const TetMesh mesh = case_mesh(study_scene(VesselParams{}, 14.24e3, 0.0), o);
  hc.setup = "Straight tube level 0, clamped ends, contact load on the 0.5 mm patch raised "
             "from 1 mN to 100 mN. After each solve the deformed volume mesh is checked for "
             "tets with non-positive signed volume (inverted): reported, not hidden.";
  const ModelSpec spec = volume_model(msm::StiffnessRule::seed001);
  for (double force : {1e-3, 1e-2, 1e-1}) {
    log << "  " << force * 1e3 << " mN" << std::endl;
    const Scene scene = study_scene(VesselParams{}, 14.24e3, force);
    const auto m = build_model(scene, mesh, spec, 0.25);
    Eigen::VectorXd x;
    HardCaseOutcome oc =
        static_outcome(spec.name + ", static, " + fmt(force * 1e3) + " mN", *m, &x);
    if (oc.finished) {
      const std::size_t inv = inverted_tets(mesh, unflatten(x));
      oc.reported += "; " + std::to_string(inv) + " inverted tets in the deformed mesh" +
                     (inv ? " (result not physical)" : "");
      oc.values["inverted_tets"] = static_cast<double>(inv);
    }
    hc.outcomes.push_back(oc);
    // Dynamic: the load applied suddenly, symplectic Euler at half the predicted step.
    const double dt = 0.5 * msm::predicted_critical_step(
                                Integrator::symplectic_euler,
                                msm::analyse_spectrum(m->problem, {.lowest = false}));
    Eigen::VectorXd xd;
    HardCaseOutcome od = dynamic_outcome(
        spec.name + ", symplectic Euler, " + fmt(force * 1e3) + " mN", m->problem,
        Integrator::symplectic_euler, dt, o.quick ? 2000 : 10000, {}, &xd);
    if (od.finished) {
      const std::size_t inv = inverted_tets(mesh, unflatten(xd));
      od.reported += "; " + std::to_string(inv) + " inverted tets at the end";
      od.values["inverted_tets"] = static_cast<double>(inv);
    }
    hc.outcomes.push_back(od);
    const FemRun r = run_fem(scene, mesh, 0.3, 1, fem::Formulation::displacement);
    HardCaseOutcome of = fem_outcome("FEM P1 (linear), " + fmt(force * 1e3) + " mN", r);
    if (r.ok) {
      std::vector<Vec3> deformed = mesh.nodes;
      for (std::size_t i = 0; i < deformed.size(); ++i) deformed[i] += r.u[i];
      const std::size_t inv = inverted_tets(mesh, deformed);
      of.reported += "; " + std::to_string(inv) + " inverted tets in the deformed mesh" +
                     (r.max_strain > 0.05 ? "; strain beyond 5 %: outside the linear reference's "
                                            "validity"
                                          : "");
      of.values["inverted_tets"] = static_cast<double>(inv);
    }
    hc.outcomes.push_back(of);
  }
  return hc;
}

}  // namespace vessel::stability_study
