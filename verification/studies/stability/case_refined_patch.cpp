// Hard case: a finely refined contact patch.
#include "verification/studies/stability/study_models.hpp"

#include "meshes/gmsh_vessel.hpp"
#include "meshes/mesh_quality.hpp"

namespace vessel::stability_study {

HardCase case_refined_patch(const StabilityOptions& o, std::ostream& log) {
  HardCase hc;
  hc.id = "refined_patch";
  hc.title = "A finely refined contact patch";
  const Scene scene = study_scene(VesselParams{}, 14.24e3, 1e-4);
  const double fine = o.quick ? 0.1e-3 : 0.05e-3;
  const TetMesh coarse = case_mesh(scene, o);
  const TetMesh mesh = refined_patch_mesh(scene.vessel, qoi_point(scene), fine, 0.5e-3);
  const MeshQuality q = compute_quality(mesh);
  hc.setup = "Straight tube meshed with gmsh (OpenCASCADE) at 1 mm, graded down to " +
             fmt(fine * 1e3) + " mm within 0.5 mm of the contact point: " +
             std::to_string(mesh.nodes.size()) + " nodes, " + std::to_string(mesh.tets.size()) +
             " tets (level 0: " + std::to_string(coarse.nodes.size()) +
             " nodes), shortest edge " + fmt(q.edge_length.min * 1e3, 3) +
             " mm, minimum dihedral " + fmt(q.dihedral_deg.min, 3) +
             "°. Contact load 0.1 mN on the 0.5 mm patch; clamped ends.";
  const int steps = o.quick ? 300 : 1000;
  for (const auto* m : {&coarse, &mesh}) {
    const std::string tag = m == &coarse ? " (level 0)" : " (refined patch)";
    log << "  " << tag << std::endl;
    for (const ModelSpec& spec : {volume_model(msm::StiffnessRule::seed001),
                                  surface_model(msm::StiffnessRule::seed000)}) {
      const auto model = build_model(scene, *m, spec, 0.25);
      hc.outcomes.push_back(step_outcome(spec.name + tag, *model, steps));
      if (spec.kind == ModelKind::volume_msm) {
        hc.outcomes.push_back(static_outcome(spec.name + tag, *model));
      }
    }
    hc.outcomes.push_back(fem_outcome(
        "FEM P2" + tag, run_fem(scene, *m, 0.3, 2, fem::Formulation::displacement)));
  }
  return hc;
}

}  // namespace vessel::stability_study
