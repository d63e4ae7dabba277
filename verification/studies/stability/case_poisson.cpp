// Hard case: near-incompressible material (ν = 0.49, 0.499, 0.5).
#include "verification/studies/stability/study_models.hpp"

#include "msm/solvers/critical_step.hpp"
#include "msm/stability/stability_search.hpp"

namespace vessel::stability_study {

HardCase case_poisson(const StabilityOptions& o, std::ostream& log) {
  HardCase hc;
  hc.id = "poisson";
  hc.title = "Near-incompressible material: ν = 0.49, 0.499, 0.5";
  const double force = 1e-4;
  hc.setup =
      "Straight tube, level 0, inlet and outlet clamped, contact load " + fmt(force * 1e3) +
      " mN on the shared 0.5 mm patch, E = 14.24 kPa. FEM P1 and P2 in the displacement "
      "formulation and Taylor–Hood P2–P1 (mixed); volume mass-spring models with each stiffness "
      "rule (static Newton; only `least-squares-fit` reads ν) and the hybrid volume model "
      "(van-gelder springs + volume term κ = λ − μ; refuses ν = 0.5). Displacement at the mesh "
      "node nearest the contact point.";
  const Scene scene = study_scene(VesselParams{}, 14.24e3, force);
  const TetMesh mesh = case_mesh(scene, o);
  for (double nu : {0.49, 0.499, 0.5}) {
    log << "  ν = " << nu << std::endl;
    const FemRun mixed = run_fem(scene, mesh, nu, 2, fem::Formulation::mixed);
    for (int degree : {1, 2}) {
      const FemRun r = run_fem(scene, mesh, nu, degree, fem::Formulation::displacement);
      HardCaseOutcome oc = fem_outcome("FEM P" + std::to_string(degree) +
                                           " displacement, ν = " + fmt(nu),
                                       r);
      if (r.ok && mixed.ok) {
        oc.reported += "; " + fmt(r.u_contact / mixed.u_contact, 3) + " × the mixed element's";
        oc.values["ratio_to_mixed"] = r.u_contact / mixed.u_contact;
      }
      hc.outcomes.push_back(oc);
    }
    hc.outcomes.push_back(fem_outcome("FEM P2–P1 mixed, ν = " + fmt(nu), mixed));
    std::vector<ModelSpec> specs;
    for (msm::StiffnessRule rule :
         {msm::StiffnessRule::seed000, msm::StiffnessRule::seed001, msm::StiffnessRule::van_gelder,
          msm::StiffnessRule::lloyd, msm::StiffnessRule::least_squares_fit}) {
      specs.push_back(volume_model(rule));
    }
    ModelSpec hybrid = volume_model(msm::StiffnessRule::van_gelder);
    hybrid.volume_term = true;
    hybrid.name = "volume / hybrid (van-gelder + volume term)";
    specs.push_back(hybrid);
    for (const ModelSpec& spec : specs) {
      // Models that ignore ν run once (at ν = 0.49).
      const bool reads_nu =
          spec.volume_term || spec.stiffness == msm::StiffnessRule::least_squares_fit;
      if (!reads_nu && nu != 0.49) continue;
      const std::string name = spec.name + (reads_nu ? ", ν = " + fmt(nu) : " (any ν)");
      try {
        const auto m = build_model(scene, mesh, spec, nu);
        HardCaseOutcome oc = static_outcome(name, *m);
        if (oc.finished && mixed.ok) {
          oc.reported += "; " + fmt(oc.values["u_contact_mm"] / (mixed.u_contact * 1e3), 3) +
                         " × the mixed FEM's at ν = " + fmt(nu);
        }
        hc.outcomes.push_back(oc);
      } catch (const std::exception& e) {
        hc.outcomes.push_back({name, false, false, {}, "refused: " + short_error(e.what()), {}});
      }
    }
  }
  return hc;
}

}  // namespace vessel::stability_study
