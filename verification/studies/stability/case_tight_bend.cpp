// Hard case: the tight bend of the arch.
#include "verification/studies/stability/study_models.hpp"

#include "meshes/mesh_quality.hpp"

namespace vessel::stability_study {

HardCase case_tight_bend(const StabilityOptions& o, std::ostream& log) {
  HardCase hc;
  hc.id = "tight_bend";
  hc.title = "The tight bend of the arch";
  hc.setup = "180° arch, level 0, bend radius 15 mm (default), 6 mm and 4.5 mm (the wall's "
             "outer radius is 4 mm), contact load 0.1 mN on a 1 mm patch at mid-arch on the "
             "outer side of the bend, clamped ends.";
  const int steps = o.quick ? 300 : 1000;
  for (double R : {15e-3, 6e-3, 4.5e-3}) {
    log << "  R = " << R * 1e3 << " mm" << std::endl;
    VesselParams params;
    params.kind = VesselKind::arch;
    params.bend_radius = R;
    const Scene scene = study_scene(params, 14.24e3, 1e-4, 1e-3);
    const std::string tag = ", R = " + fmt(R * 1e3) + " mm";
    TetMesh mesh;
    try {
      mesh = case_mesh(scene, o);
    } catch (const std::exception& e) {
      hc.outcomes.push_back({"gmsh" + tag, false, {}, {}, "meshing failed: " + short_error(e.what()), {}});
      continue;
    }
    const MeshQuality q = compute_quality(mesh);
    hc.outcomes.push_back({"mesh" + tag, true, {}, {},
                           std::to_string(mesh.nodes.size()) + " nodes, minimum dihedral " +
                               fmt(q.dihedral_deg.min, 3) + "°, shortest edge " +
                               fmt(q.edge_length.min * 1e3, 3) + " mm",
                           {{"min_dihedral_deg", q.dihedral_deg.min}}});
    const ModelSpec spec = volume_model(msm::StiffnessRule::seed001);
    const auto m = build_model(scene, mesh, spec, 0.25);
    hc.outcomes.push_back(step_outcome(spec.name + tag, *m, steps));
    hc.outcomes.push_back(static_outcome(spec.name + tag, *m));
    hc.outcomes.push_back(fem_outcome(
        "FEM P2" + tag, run_fem(scene, mesh, 0.3, 2, fem::Formulation::displacement)));
  }
  return hc;
}

}  // namespace vessel::stability_study
