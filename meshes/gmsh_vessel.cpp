#include "meshes/gmsh_vessel.hpp"

#include <gmsh.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <mutex>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include "meshes/foundation/errors.hpp"

namespace vessel {

namespace {

/// gmsh is a process-wide singleton: one session at a time (studies mesh from several threads),
/// initialised for one generation and always finalised.
class GmshSession {
 public:
  explicit GmshSession(const MeshingOptions& options) : lock_(session_mutex()) {
    gmsh::initialize(0, nullptr, /*readConfigFiles=*/false);
    gmsh::option::setNumber("General.Terminal", options.verbose ? 1 : 0);
    gmsh::option::setNumber("General.NumThreads", 1);
    gmsh::model::add("vessel");
  }
  ~GmshSession() { gmsh::finalize(); }
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;

 private:
  static std::mutex& session_mutex() {
    static std::mutex m;
    return m;
  }
  std::unique_lock<std::mutex> lock_;
};

/// gmsh's Delaunay tetrahedralisation (algorithm 1), its optimiser reshaping tets of quality below
/// 0.6 (default 0.3: at level 2 of the tube the smallest dihedral angle rises from 6.0° to 8.0°,
/// at level 1 from 13.8° to 18.4°). Not HXT (algorithm 10), though it is 2–3× faster and better
/// shaped: gmsh 4.8 hands HXT the surface nodes ordered by their addresses in memory
/// (std::set<MVertex *> in meshGRegionHxt.cpp, fixed upstream later), so its mesh changes with
/// the heap's history: between two generations in one process, and with the OpenMP threads.
/// A mesh must be a function of its parameters alone: the mesh cache and the baselines key on them.
void use_reproducible_volume_mesher() {
  gmsh::option::setNumber("Mesh.Algorithm3D", 1);
  gmsh::option::setNumber("Mesh.OptimizeThreshold", 0.6);
}

/// A point of the inlet cross-section at local polar coordinates (ρ, θ) around the centreline.
/// Tube: the section lies in z = 0 around the z axis. Arch: it lies in y = 0 around (R, 0, 0) and
/// is revolved about the z axis.
Vec3 section_point(const VesselParams& p, double rho, double theta) {
  if (p.kind == VesselKind::straight) return {rho * std::cos(theta), rho * std::sin(theta), 0.0};
  return {p.bend_radius + rho * std::cos(theta), 0.0, rho * std::sin(theta)};
}

struct Section {
  std::vector<int> patches;  ///< four quarter-annulus plane surfaces
  std::vector<int> arcs;     ///< inner and outer arcs (transfinite along the circumference)
  std::vector<int> radials;  ///< radial lines (transfinite through the wall)
};

Section build_section(const VesselParams& p) {
  namespace geo = gmsh::model::geo;
  const Vec3 c = section_point(p, 0.0, 0.0);
  const int centre = geo::addPoint(c.x(), c.y(), c.z());
  std::array<int, 4> inner{};
  std::array<int, 4> outer{};
  for (int i = 0; i < 4; ++i) {
    const double theta = i * std::numbers::pi / 2.0;
    const Vec3 a = section_point(p, p.inner_radius, theta);
    const Vec3 b = section_point(p, p.outer_radius(), theta);
    inner[i] = geo::addPoint(a.x(), a.y(), a.z());
    outer[i] = geo::addPoint(b.x(), b.y(), b.z());
  }
  Section s;
  std::array<int, 4> radial{};
  for (int i = 0; i < 4; ++i) {
    radial[i] = geo::addLine(inner[i], outer[i]);
    s.radials.push_back(radial[i]);
  }
  for (int i = 0; i < 4; ++i) {
    const int j = (i + 1) % 4;
    const int inner_arc = geo::addCircleArc(inner[i], centre, inner[j]);
    const int outer_arc = geo::addCircleArc(outer[i], centre, outer[j]);
    s.arcs.push_back(inner_arc);
    s.arcs.push_back(outer_arc);
    const int loop = geo::addCurveLoop({radial[i], outer_arc, -radial[j], -inner_arc});
    s.patches.push_back(geo::addPlaneSurface({loop}));
  }
  return s;
}

/// Output of one gmsh extrusion of the four patches: per patch [top, volume, 4 laterals].
struct Sweep {
  std::vector<int> tops;
  std::vector<int> volumes;
  std::vector<int> laterals;
};

Sweep parse_sweep(const gmsh::vectorpair& out, std::size_t n_patches) {
  constexpr std::size_t kStride = 6;
  if (out.size() != n_patches * kStride) {
    throw std::runtime_error("gmsh extrusion returned " + std::to_string(out.size()) +
                             " entities, expected " + std::to_string(n_patches * kStride));
  }
  Sweep s;
  for (std::size_t i = 0; i < n_patches; ++i) {
    const auto* e = &out[i * kStride];
    if (e[0].first != 2 || e[1].first != 3) {
      throw std::runtime_error("unexpected entity layout in gmsh extrusion output");
    }
    s.tops.push_back(e[0].second);
    s.volumes.push_back(e[1].second);
    for (std::size_t k = 2; k < kStride; ++k) s.laterals.push_back(e[k].second);
  }
  return s;
}

struct VesselEntities {
  std::vector<int> inlet, outlet, inner_wall, outer_wall, wall;
};

/// Sorts lateral surfaces into inner wall, outer wall or interior (the radial cut planes) by the
/// distance of their corner points from the centreline: all at a → inner, all at b → outer.
void classify_laterals(const VesselParams& p, const std::vector<int>& laterals,
                       VesselEntities& entities) {
  const double tol = 1e-6 * p.outer_radius();
  for (int surface : laterals) {
    gmsh::vectorpair corners;
    gmsh::model::getBoundary({{2, surface}}, corners, /*combined=*/false, /*oriented=*/false,
                             /*recursive=*/true);
    bool all_inner = true;
    bool all_outer = true;
    for (const auto& [dim, tag] : corners) {
      std::vector<double> xyz;
      gmsh::model::getValue(0, tag, {}, xyz);
      const double rho = distance_from_centreline(p, Vec3(xyz[0], xyz[1], xyz[2]));
      all_inner = all_inner && std::abs(rho - p.inner_radius) < tol;
      all_outer = all_outer && std::abs(rho - p.outer_radius()) < tol;
    }
    if (all_inner) entities.inner_wall.push_back(surface);
    if (all_outer) entities.outer_wall.push_back(surface);
  }
}

VesselEntities build_geometry(const VesselParams& p) {
  namespace geo = gmsh::model::geo;
  const Section section = build_section(p);
  const bool structured = p.style == MeshStyle::structured;
  const StructuredCounts counts = structured_counts(p);
  if (structured) {
    for (int arc : section.arcs)
      geo::mesh::setTransfiniteCurve(arc, counts.circumferential / 4 + 1);
    for (int line : section.radials) geo::mesh::setTransfiniteCurve(line, counts.radial + 1);
    for (int patch : section.patches) geo::mesh::setTransfiniteSurface(patch);
  }

  VesselEntities entities;
  entities.inlet = section.patches;
  gmsh::vectorpair sources;
  for (int patch : section.patches) sources.emplace_back(2, patch);
  std::vector<int> laterals;
  if (p.kind == VesselKind::straight) {
    gmsh::vectorpair out;
    std::vector<int> layers;
    if (structured) layers = {counts.axial};
    geo::extrude(sources, 0.0, 0.0, p.length, out, layers);
    const Sweep sweep = parse_sweep(out, sources.size());
    entities.outlet = sweep.tops;
    entities.wall = sweep.volumes;
    laterals = sweep.laterals;
  } else {
    // The built-in kernel revolves by less than π at once: two quarter turns make the 180° arch.
    std::vector<int> layers;
    if (structured) layers = {counts.axial / 2};
    for (int half = 0; half < 2; ++half) {
      gmsh::vectorpair out;
      geo::revolve(sources, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, std::numbers::pi / 2.0, out, layers);
      const Sweep sweep = parse_sweep(out, sources.size());
      entities.wall.insert(entities.wall.end(), sweep.volumes.begin(), sweep.volumes.end());
      laterals.insert(laterals.end(), sweep.laterals.begin(), sweep.laterals.end());
      sources.clear();
      for (int top : sweep.tops) sources.emplace_back(2, top);
      if (half == 1) entities.outlet = sweep.tops;
    }
  }
  geo::synchronize();
  classify_laterals(p, laterals, entities);
  if (entities.inner_wall.empty() || entities.outer_wall.empty()) {
    throw std::runtime_error("gmsh geometry: could not identify the inner and outer walls");
  }
  return entities;
}

void add_physical_groups(const VesselEntities& e) {
  const std::map<std::string_view, const std::vector<int>*> members{
      {group_names::inlet, &e.inlet},
      {group_names::outlet, &e.outlet},
      {group_names::inner_wall, &e.inner_wall},
      {group_names::outer_wall, &e.outer_wall},
      {group_names::wall, &e.wall}};
  for (const auto& spec : kVesselGroups) {
    // gmsh 4.8: addPhysicalGroup takes no name; setPhysicalName names it afterwards.
    gmsh::model::addPhysicalGroup(spec.dim, *members.at(spec.name), spec.tag);
    gmsh::model::setPhysicalName(spec.dim, spec.tag, std::string(spec.name));
  }
}

/// Copies gmsh's mesh of the physical groups into a TetMesh (0-based contiguous node indices).
TetMesh extract_mesh() {
  TetMesh mesh;
  std::vector<std::size_t> node_tags;
  std::vector<double> coords;
  std::vector<double> parametric;
  gmsh::model::mesh::getNodes(node_tags, coords, parametric, -1, -1, false, false);
  std::unordered_map<std::size_t, int> index;
  index.reserve(node_tags.size());
  mesh.nodes.reserve(node_tags.size());
  for (std::size_t i = 0; i < node_tags.size(); ++i) {
    index.emplace(node_tags[i], static_cast<int>(i));
    mesh.nodes.emplace_back(coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]);
  }
  for (const auto& spec : kVesselGroups) {
    PhysicalGroup group{std::string(spec.name), spec.dim, spec.tag, {}};
    std::vector<int> entity_tags;
    gmsh::model::getEntitiesForPhysicalGroup(spec.dim, spec.tag, entity_tags);
    const int type = spec.dim == 3 ? 4 : 2;  // gmsh: 4 = 4-node tet, 2 = 3-node triangle
    for (int entity : entity_tags) {
      std::vector<std::size_t> element_tags;
      std::vector<std::size_t> element_nodes;
      gmsh::model::mesh::getElementsByType(type, element_tags, element_nodes, entity);
      for (std::size_t e = 0; e < element_tags.size(); ++e) {
        if (spec.dim == 3) {
          Tet t{};
          for (int k = 0; k < 4; ++k) t[k] = index.at(element_nodes[4 * e + k]);
          group.elements.push_back(static_cast<int>(mesh.tets.size()));
          mesh.tets.push_back(t);
        } else {
          Triangle t{};
          for (int k = 0; k < 3; ++k) t[k] = index.at(element_nodes[3 * e + k]);
          group.elements.push_back(static_cast<int>(mesh.triangles.size()));
          mesh.triangles.push_back(t);
        }
      }
    }
    mesh.groups.push_back(std::move(group));
  }
  return mesh;
}

}  // namespace

TetMesh generate_vessel_mesh(const VesselParams& params, const MeshingOptions& options) {
  validate(params);
  GmshSession session(options);
  const VesselEntities entities = build_geometry(params);
  add_physical_groups(entities);
  if (params.style == MeshStyle::unstructured) {
    const double h = unstructured_mesh_size(params);
    gmsh::option::setNumber("Mesh.MeshSizeMin", 0.5 * h);
    gmsh::option::setNumber("Mesh.MeshSizeMax", h);
    gmsh::option::setNumber("Mesh.MeshSizeFromPoints", 0);
    use_reproducible_volume_mesher();
  }
  gmsh::model::mesh::generate(3);
  TetMesh mesh = extract_mesh();
  remove_unused_nodes(mesh);
  sort_elements(mesh);
  orient_tets(mesh);
  orient_boundary_outward(mesh);
  require_vessel_groups(mesh, "generated " + describe(params));
  return mesh;
}

namespace {

/// The straight tube by OpenCASCADE (a cylinder cut from a cylinder), its groups added.
void build_occ_tube(const VesselParams& params) {
  const double a = params.inner_radius, b = params.outer_radius(), L = params.length;
  const int outer = gmsh::model::occ::addCylinder(0, 0, 0, 0, 0, L, b);
  const int inner = gmsh::model::occ::addCylinder(0, 0, 0, 0, 0, L, a);
  gmsh::vectorpair out;
  std::vector<gmsh::vectorpair> out_map;
  gmsh::model::occ::cut({{3, outer}}, {{3, inner}}, out, out_map);
  gmsh::model::occ::synchronize();
  // Classify the faces geometrically (OCC renumbers them; bounding boxes padded ~1e-7).
  gmsh::vectorpair faces;
  gmsh::model::getEntities(faces, 2);
  std::vector<int> inlet, outlet, inner_wall, outer_wall, volumes;
  const double tol = 1e-5;
  for (const auto& [dim, tag] : faces) {
    double x0, y0, z0, x1, y1, z1;
    gmsh::model::getBoundingBox(dim, tag, x0, y0, z0, x1, y1, z1);
    if (z1 < tol)
      inlet.push_back(tag);
    else if (z0 > L - tol)
      outlet.push_back(tag);
    else if (x1 < a + tol)
      inner_wall.push_back(tag);
    else
      outer_wall.push_back(tag);
  }
  gmsh::vectorpair vols;
  gmsh::model::getEntities(vols, 3);
  for (const auto& v : vols) volumes.push_back(v.second);
  for (const auto& spec : kVesselGroups) {
    const std::vector<int>& tags = spec.name == group_names::inlet        ? inlet
                                   : spec.name == group_names::outlet     ? outlet
                                   : spec.name == group_names::inner_wall ? inner_wall
                                   : spec.name == group_names::outer_wall ? outer_wall
                                                                          : volumes;
    gmsh::model::addPhysicalGroup(spec.dim, tags, spec.tag);
    gmsh::model::setPhysicalName(spec.dim, spec.tag, std::string(spec.name));
  }
}

}  // namespace

TetMesh refined_patch_mesh(const VesselParams& params, const Vec3& point, double fine,
                           double radius) {
  return refined_balls_mesh(params, {RefinedBall{point, radius}}, fine);
}

TetMesh refined_balls_mesh(const VesselParams& params, const std::vector<RefinedBall>& balls,
                           double fine) {
  validate(params);
  if (!params.parametric()) {
    throw InputError("refined_patch_mesh: expected a straight vessel or an arch");
  }
  const bool radii_ok = std::all_of(balls.begin(), balls.end(), [](const RefinedBall& b) {
    return b.radius >= 0.0 && b.size >= 0.0;
  });
  if (!(fine > 0.0) || balls.empty() || !radii_ok) {
    throw InputError(
        "refined_patch_mesh: expected a positive fine size and at least one ball, each with a "
        "non-negative radius and size");
  }
  const double h = unstructured_mesh_size(params);
  GmshSession session(MeshingOptions{});
  if (params.kind == VesselKind::straight) {
    build_occ_tube(params);
  } else {
    // The arch by the built-in kernel's revolution, unstructured.
    VesselParams p = params;
    p.style = MeshStyle::unstructured;
    add_physical_groups(build_geometry(p));
  }
  // Size field: the ball's size within each ball, growing linearly to h over 2 mm; the smallest
  // wins.
  const int f = gmsh::model::mesh::field::add("MathEval");
  std::ostringstream expr;
  expr << std::setprecision(17);
  for (const RefinedBall& b : balls) {
    const double size = b.size > 0.0 ? b.size : fine;
    // Each coordinate in parentheses: "y--1e-05" (a negative one) does not parse.
    expr << "Min(" << size << " + Max(0, Sqrt((x-(" << b.centre.x() << "))^2+(y-(" << b.centre.y()
         << "))^2+(z-(" << b.centre.z() << "))^2) - " << b.radius << ") * " << (h - size) / 2e-3
         << ", ";
  }
  expr << h << std::string(balls.size(), ')');
  gmsh::model::mesh::field::setString(f, "F", expr.str());
  gmsh::model::mesh::field::setAsBackgroundMesh(f);
  gmsh::option::setNumber("Mesh.MeshSizeFromPoints", 0);
  gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
  gmsh::option::setNumber("Mesh.MeshSizeExtendFromBoundary", 0);
  gmsh::option::setNumber("Mesh.MeshSizeMax", h);
  use_reproducible_volume_mesher();
  gmsh::model::mesh::generate(3);
  TetMesh mesh = extract_mesh();
  remove_unused_nodes(mesh);
  sort_elements(mesh);
  orient_tets(mesh);
  orient_boundary_outward(mesh);
  require_vessel_groups(mesh, "refined-patch mesh");
  return mesh;
}

std::string gmsh_version() { return GMSH_API_VERSION; }

}  // namespace vessel
