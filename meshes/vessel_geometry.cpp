#include "meshes/vessel_geometry.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

#include "meshes/foundation/errors.hpp"

namespace vessel {

namespace {

void require_positive(const char* name, double value) {
  if (!std::isfinite(value) || value <= 0.0) {
    std::ostringstream msg;
    msg << "vessel parameter '" << name << "' = " << value
        << " m is invalid: expected a finite value > 0 (lengths are in metres)";
    throw InputError(msg.str());
  }
}

/// Circumferential divisions at level 0: 24 (6 per quarter) gives ≈0.9 mm spacing on the default.
constexpr int kCircumferentialLevel0 = 24;
constexpr int kRadialLevel0 = 2;

}  // namespace

double VesselParams::centreline_length() const {
  require_parametric(*this, "the centreline's length");
  return kind == VesselKind::straight ? length : std::numbers::pi * bend_radius;
}

void require_parametric(const VesselParams& p, const std::string& what) {
  if (p.parametric()) return;
  throw InputError(what + " needs a parametric vessel (straight or arch, with a centreline); got " +
                   describe(p));
}

void validate(const VesselParams& p) {
  if (p.level < 0 || p.level > kMaxMeshLevel) {
    throw InputError("mesh level " + std::to_string(p.level) + " is out of range: expected 0.." +
                     std::to_string(kMaxMeshLevel));
  }
  if (!p.parametric()) {
    if (p.file.empty()) throw InputError("vessel: expected a file for a " + to_string(p.kind) + " vessel");
    if (p.kind == VesselKind::mesh_file && p.level != 0) {
      throw InputError(p.file.string() + ": mesh level " + std::to_string(p.level) +
                       " asked of a mesh file; expected level 0 only (a .msh file is used as "
                       "given: levels do not refine it)");
    }
    if (p.kind == VesselKind::lumen) require_positive("wall_thickness", p.wall_thickness);
    if (!std::isfinite(p.file_scale) || p.file_scale <= 0.0) {
      throw InputError(p.file.string() + ": unit scale " + std::to_string(p.file_scale) +
                       ": expected a finite value > 0");
    }
    return;
  }
  require_positive("inner_radius", p.inner_radius);
  require_positive("wall_thickness", p.wall_thickness);
  if (p.kind == VesselKind::straight) {
    require_positive("length", p.length);
  } else {
    require_positive("bend_radius", p.bend_radius);
    if (p.outer_radius() >= p.bend_radius) {
      std::ostringstream msg;
      msg << "vessel parameter 'wall_thickness' = " << p.wall_thickness
          << " m is too thick for the arch: the outer radius inner_radius + wall_thickness = "
          << p.outer_radius() << " m must be smaller than bend_radius = " << p.bend_radius
          << " m, or the wall crosses the bend's axis";
      throw InputError(msg.str());
    }
  }
  if (p.wall_thickness > 10.0 * p.inner_radius) {
    std::ostringstream msg;
    msg << "vessel parameter 'wall_thickness' = " << p.wall_thickness
        << " m is more than 10 × inner_radius = " << p.inner_radius
        << " m; expected a tube, not a solid rod (the lumen would vanish in the mesh)";
    throw InputError(msg.str());
  }
}

double analytic_wall_volume(const VesselParams& p) {
  const double a = p.inner_radius;
  const double b = p.outer_radius();
  return std::numbers::pi * (b * b - a * a) * p.centreline_length();
}

double analytic_lateral_area(const VesselParams& p, double radius) {
  return 2.0 * std::numbers::pi * radius * p.centreline_length();
}

double analytic_end_area(const VesselParams& p) {
  const double a = p.inner_radius;
  const double b = p.outer_radius();
  return std::numbers::pi * (b * b - a * a);
}


CentrelineCoordinates centreline_coordinates(const VesselParams& p, const Vec3& x) {
  require_parametric(p, "centreline coordinates");
  CentrelineCoordinates c;
  Vec3 offset;  // from the centreline to x
  Vec3 outward;  // θ = 0 direction in the cross-section
  Vec3 binormal;  // θ = π/2 direction
  if (p.kind == VesselKind::straight) {
    c.s = x.z();
    offset = Vec3(x.x(), x.y(), 0.0);
    outward = Vec3::UnitX();
    binormal = Vec3::UnitY();
  } else {
    const double phi = std::atan2(x.y(), x.x());
    c.s = p.bend_radius * phi;
    outward = Vec3(std::cos(phi), std::sin(phi), 0.0);
    offset = x - p.bend_radius * outward;
    binormal = Vec3::UnitZ();
  }
  c.rho = offset.norm();
  c.theta = std::atan2(offset.dot(binormal), offset.dot(outward));
  if (c.rho > 0.0) c.e_rho = offset / c.rho;
  return c;
}

double distance_from_centreline(const VesselParams& p, const Vec3& x) {
  return centreline_coordinates(p, x).rho;
}

StructuredCounts structured_counts(const VesselParams& p) {
  const int scale = 1 << p.level;
  StructuredCounts c;
  c.circumferential = kCircumferentialLevel0 * scale;
  c.radial = kRadialLevel0 * scale;
  // Axial spacing ≈ twice the mid-wall circumferential spacing at level 0.
  const double mid_radius = p.inner_radius + 0.5 * p.wall_thickness;
  const double circ_spacing = 2.0 * std::numbers::pi * mid_radius / kCircumferentialLevel0;
  int axial0 = static_cast<int>(std::lround(p.centreline_length() / (2.0 * circ_spacing)));
  axial0 = std::max(axial0, 2);
  if (p.kind == VesselKind::arch && axial0 % 2 != 0) ++axial0;  // two 90° halves
  c.axial = axial0 * scale;
  return c;
}

double unstructured_mesh_size(const VesselParams& p) {
  return p.wall_thickness / static_cast<double>(1 << p.level);
}

std::string to_string(VesselKind kind) {
  switch (kind) {
    case VesselKind::straight: return "straight";
    case VesselKind::arch: return "arch";
    case VesselKind::mesh_file: return "file";
    case VesselKind::lumen: return "lumen";
  }
  return "?";
}

std::string to_string(MeshStyle style) {
  return style == MeshStyle::structured ? "structured" : "unstructured";
}

std::string describe(const VesselParams& p) {
  std::ostringstream s;
  if (p.kind == VesselKind::mesh_file) {
    s << "vessel mesh " << p.file.string() << " (as given, level 0)";
    return s.str();
  }
  if (p.kind == VesselKind::lumen) {
    s << "lumen " << p.file.string() << (p.file_scale != 1.0 ? " (scaled to m)" : "")
      << ", wall " << p.wall_thickness * 1e3 << " mm extruded outward, level " << p.level;
    return s.str();
  }
  s << to_string(p.kind) << " vessel, " << to_string(p.style) << " level " << p.level
    << ": inner radius " << p.inner_radius * 1e3 << " mm, wall " << p.wall_thickness * 1e3
    << " mm, ";
  if (p.kind == VesselKind::straight) {
    s << "length " << p.length * 1e3 << " mm";
  } else {
    s << "bend radius " << p.bend_radius * 1e3 << " mm (180°)";
  }
  return s.str();
}

}  // namespace vessel
