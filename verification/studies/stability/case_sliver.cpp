// Hard case: sliver tetrahedra (minimum dihedral angle below 5°).
#include "verification/studies/stability/study_models.hpp"

#include <algorithm>
#include <set>

#include "meshes/mesh_quality.hpp"

namespace vessel::stability_study {

namespace {

/// Moves one interior node towards the opposite face of one of its tets until that tet's
/// smallest dihedral angle is below 5°, keeping every tet positively oriented.
struct Sliver {
  TetMesh mesh;
  int node = -1;
  double min_dihedral_deg = 180.0;
};

Sliver make_sliver(const TetMesh& mesh, const Vec3& near) {
  std::set<int> boundary;
  for (const Triangle& t : mesh.triangles)
    for (int n : t) boundary.insert(n);
  std::vector<int> order;
  for (int i = 0; i < static_cast<int>(mesh.nodes.size()); ++i) {
    if (!boundary.count(i)) order.push_back(i);
  }
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return (mesh.nodes[a] - near).squaredNorm() < (mesh.nodes[b] - near).squaredNorm();
  });
  std::vector<std::vector<int>> tets_of(mesh.nodes.size());
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    for (int n : mesh.tets[t]) tets_of[n].push_back(static_cast<int>(t));
  for (std::size_t k = 0; k < std::min<std::size_t>(order.size(), 50); ++k) {
    const int n = order[k];
    for (int t : tets_of[n]) {
      const Tet& tet = mesh.tets[t];
      std::vector<int> face;
      for (int v : tet)
        if (v != n) face.push_back(v);
      const Vec3 a = mesh.nodes[face[0]], b = mesh.nodes[face[1]], c = mesh.nodes[face[2]];
      const Vec3 normal = (b - a).cross(c - a).normalized();
      const double height = (mesh.nodes[n] - a).dot(normal);
      for (double f : {0.8, 0.9, 0.95, 0.97, 0.98, 0.99}) {
        Sliver s{mesh, n, 180.0};
        s.mesh.nodes[n] = mesh.nodes[n] - f * height * normal;
        bool valid = true;
        for (int u : tets_of[n]) {
          const Tet& q = s.mesh.tets[u];
          if (!(signed_volume(s.mesh.nodes[q[0]], s.mesh.nodes[q[1]], s.mesh.nodes[q[2]],
                              s.mesh.nodes[q[3]]) > 0))
            valid = false;
        }
        if (!valid) break;
        const Tet& q = s.mesh.tets[t];
        const auto ang = dihedral_angles_deg(s.mesh.nodes[q[0]], s.mesh.nodes[q[1]],
                                             s.mesh.nodes[q[2]], s.mesh.nodes[q[3]]);
        s.min_dihedral_deg = *std::min_element(ang.begin(), ang.end());
        if (s.min_dihedral_deg < 5.0) return s;
      }
    }
  }
  throw std::runtime_error("could not make a sliver tet near the contact point");
}

}  // namespace

HardCase case_sliver(const StabilityOptions& o, std::ostream& log) {
  HardCase hc;
  hc.id = "sliver";
  hc.title = "Sliver tetrahedra (minimum dihedral angle below 5°)";
  const Scene scene = study_scene(VesselParams{}, 14.24e3, 1e-4);
  const TetMesh mesh = case_mesh(scene, o);
  const Sliver s = make_sliver(mesh, qoi_point(scene) + Vec3(0.5e-3, 0, 0));
  const MeshQuality q0 = compute_quality(mesh), q1 = compute_quality(s.mesh);
  hc.setup = "Straight tube level 0 with one interior node near the contact point moved towards "
             "the opposite face of one of its tets: minimum dihedral angle " +
             fmt(q0.dihedral_deg.min, 3) + "° → " + fmt(q1.dihedral_deg.min, 3) +
             "°, smallest tet volume " + fmt(q0.volume.min * 1e9, 3) + " → " +
             fmt(q1.volume.min * 1e9, 3) + " mm³, no tet inverted (" +
             std::to_string(q1.inverted) + "). Contact load 0.1 mN; clamped ends.";
  const int steps = o.quick ? 300 : 1000;
  for (const auto* m : {&mesh, &s.mesh}) {
    const std::string tag = m == &mesh ? " (regular mesh)" : " (sliver mesh)";
    log << "  " << tag << std::endl;
    for (msm::StiffnessRule rule : {msm::StiffnessRule::seed001, msm::StiffnessRule::van_gelder}) {
      const ModelSpec spec = volume_model(rule);
      const auto model = build_model(scene, *m, spec, 0.25);
      hc.outcomes.push_back(step_outcome(spec.name + tag, *model, steps));
      hc.outcomes.push_back(static_outcome(spec.name + tag, *model));
    }
    for (int degree : {1, 2}) {
      hc.outcomes.push_back(
          fem_outcome("FEM P" + std::to_string(degree) + tag,
                      run_fem(scene, *m, 0.3, degree, fem::Formulation::displacement)));
    }
  }
  return hc;
}

}  // namespace vessel::stability_study
