// Hard case: E from 1 kPa to 1 MPa at a fixed step.
#include "verification/studies/stability/study_models.hpp"

#include "msm/solvers/critical_step.hpp"
#include "msm/stability/stability_search.hpp"

namespace vessel::stability_study {

HardCase case_youngs_modulus(const StabilityOptions& o, std::ostream& log) {
  HardCase hc;
  hc.id = "youngs_modulus";
  hc.title = "E from 1 kPa to 1 MPa at a fixed step";
  const int steps = o.quick ? 1000 : 5000;
  const ModelSpec spec = volume_model(msm::StiffnessRule::seed001);
  const double E0 = 14.24e3;
  const Scene unloaded = study_scene(VesselParams{}, E0, 0.0);
  const TetMesh mesh = case_mesh(unloaded, o);
  const auto ref = build_model(unloaded, mesh, spec, 0.25);
  const double dt =
      0.9 * msm::predicted_critical_step(Integrator::symplectic_euler,
                                         msm::analyse_spectrum(ref->problem, {.lowest = false}));
  hc.setup = "Volume model (seed001), straight tube level 0, contact load 0.1 mN × E/14.24 kPa "
             "(the same strain at every E), suddenly applied, undamped; every run at dt = " +
             fmt(dt) + " s (0.9 × the predicted critical step at E = 14.24 kPa), " +
             std::to_string(steps) + " steps (20 for implicit Euler). FEM P1 static at the "
             "extremes.";
  for (double E : {1e3, 1e4, E0, 1e5, 1e6}) {
    log << "  E = " << E << " Pa" << std::endl;
    const double force = 1e-4 * E / E0;
    const Scene scene = study_scene(VesselParams{}, E, force);
    const auto m = build_model(scene, mesh, spec, 0.25);
    const double crit = msm::predicted_critical_step(
        Integrator::symplectic_euler, msm::analyse_spectrum(m->problem, {.lowest = false}));
    for (Integrator in : {Integrator::symplectic_euler, Integrator::verlet,
                          Integrator::implicit_euler}) {
      HardCaseOutcome oc =
          dynamic_outcome(spec.name + ", " + msm::to_string(in) + ", E = " + fmt(E) + " Pa",
                          m->problem, in, dt, in == Integrator::implicit_euler ? 20 : steps);
      oc.reported += "; predicted critical step " + fmt(crit) + " s (dt/critical " +
                     fmt(dt / crit, 3) + ")";
      oc.values["critical_dt_s"] = crit;
      hc.outcomes.push_back(oc);
    }
    if (E == 1e3 || E == 1e6) {
      const FemRun r = run_fem(scene, mesh, 0.3, 1, fem::Formulation::displacement);
      hc.outcomes.push_back(fem_outcome("FEM P1, ν = 0.3, E = " + fmt(E) + " Pa", r));
    }
  }
  return hc;
}

}  // namespace vessel::stability_study
