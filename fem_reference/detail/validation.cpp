#include "fem_reference/detail/validation.hpp"

#include <cmath>
#include <sstream>
#include <string>

#include "meshes/foundation/errors.hpp"

namespace vessel::fem::detail {

namespace {

/// The first invalid material, element or solver parameter, or "" if there is none.
std::string parameter_error(const ElasticityProblem& p) {
  const auto& m = p.material;
  const auto& o = p.options;
  std::ostringstream msg;
  if (!std::isfinite(m.youngs_modulus) || m.youngs_modulus <= 0.0) {
    msg << "Young's modulus E = " << m.youngs_modulus << " Pa is invalid: expected E > 0";
  } else if (!std::isfinite(m.poisson_ratio) || m.poisson_ratio < 0.0 || m.poisson_ratio > 0.5) {
    msg << "Poisson's ratio nu = " << m.poisson_ratio << " is invalid: expected 0 <= nu <= 0.5";
  } else if (!std::isfinite(m.density) || m.density < 0.0) {
    msg << "density = " << m.density << " kg/m^3 is invalid: expected a finite value >= 0";
  } else if (o.degree != 1 && o.degree != 2) {
    msg << "element degree = " << o.degree << " is invalid: expected 1 or 2";
  } else if (m.poisson_ratio == 0.5 && o.formulation == Formulation::displacement) {
    msg << "Poisson's ratio nu = 0.5 (incompressible) cannot be solved with the displacement-only "
           "formulation (lambda is infinite): use the mixed formulation (Taylor-Hood P2-P1)";
  } else if (!(o.mixed_threshold > 0.0)) {
    msg << "mixed threshold = " << o.mixed_threshold << " is invalid: expected > 0";
  } else if (!(o.cg_relative_tolerance > 0.0) || !std::isfinite(o.cg_relative_tolerance)) {
    msg << "CG tolerance = " << o.cg_relative_tolerance << " is invalid: expected > 0";
  } else if (o.max_iterations == 0) {
    msg << "CG iteration limit = 0 is invalid: expected >= 1";
  } else if (!p.gravity.allFinite()) {
    msg << "gravity must be finite";
  }
  return msg.str();
}

void validate_supports(const TetMesh& mesh, const ElasticityProblem& p) {
  for (const auto& d : p.dirichlet) {
    (void)mesh.require_group(d.group, 2, "FEM boundary condition");
    if (d.kind == DirichletCondition::Kind::roller && (d.component < 0 || d.component > 2)) {
      throw InputError("roller on '" + d.group + "': component " + std::to_string(d.component) +
                       " is invalid: expected 0, 1 or 2 (x, y, z)");
    }
  }
  for (const auto& pc : p.point_constraints) {
    if (pc.component < 0 || pc.component > 2) {
      throw InputError("point constraint component " + std::to_string(pc.component) +
                       " is invalid: expected 0, 1 or 2");
    }
  }
}

void validate_patch(const TetMesh& mesh, const TractionPatch& patch) {
  const auto on_mesh = [&](int t) {
    return t >= 0 && static_cast<std::size_t>(t) < mesh.triangles.size();
  };
  if (!patch.traction.allFinite()) throw InputError("traction patch: traction is not finite");
  for (int t : patch.triangles) {
    if (!on_mesh(t)) {
      throw InputError("traction patch refers to triangle " + std::to_string(t) +
                       " which is not in the mesh");
    }
  }
  for (std::size_t q = 0; q < patch.points.size(); ++q) {
    const SurfacePoint& point = patch.points[q];
    const std::string which = "traction patch point " + std::to_string(q);
    if (!on_mesh(point.triangle)) {
      throw InputError(which + " lies on triangle " + std::to_string(point.triangle) +
                       ", which is not in the mesh (" + std::to_string(mesh.triangles.size()) +
                       " triangles)");
    }
    if (!point.barycentric.allFinite()) {
      throw InputError(which + ": barycentric coordinates are not finite");
    }
    if (!std::isfinite(point.weight)) throw InputError(which + ": weight is not finite");
  }
}

}  // namespace

void validate_problem(const TetMesh& mesh, const ElasticityProblem& p) {
  if (const std::string msg = parameter_error(p); !msg.empty()) throw InputError(msg);
  validate_supports(mesh, p);
  for (const auto& pr : p.pressures) {
    (void)mesh.require_group(pr.group, 2, "FEM pressure load");
    if (!std::isfinite(pr.pressure))
      throw InputError("pressure on '" + pr.group + "' is not finite");
  }
  for (const auto& patch : p.patches) validate_patch(mesh, patch);
}

bool uses_mixed_formulation(const ElasticityProblem& p) {
  const auto& o = p.options;
  const double nu = p.material.poisson_ratio;
  return o.formulation == Formulation::mixed ||
         (o.formulation == Formulation::automatic && (nu >= o.mixed_threshold || nu == 0.5));
}

}  // namespace vessel::fem::detail
