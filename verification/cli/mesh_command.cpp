/// `vesselverify mesh`: generate (or load) a vessel mesh, print counts and quality, write it.
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>

#include "meshes/foundation/atomic_file.hpp"
#include "meshes/foundation/errors.hpp"
#include "meshes/lumen_mesh.hpp"
#include "meshes/mesh_quality.hpp"
#include "meshes/msh_io.hpp"
#include "meshes/stl_io.hpp"
#include "meshes/vtu_io.hpp"
#include "verification/cli/commands.hpp"
#include "verification/cli/vessel_options.hpp"
#include "verification/harness/results.hpp"

namespace vessel::cli {

namespace fs = std::filesystem;

namespace {

struct MeshCommandOptions {
  VesselOptions vessel;
  fs::path input;
  fs::path output;
  std::string msh_version = "4.1";
  fs::path vtu;
  fs::path stl;
  std::string stl_group = std::string(group_names::inner_wall);
  fs::path stats_json;
};

nlohmann::json stats_to_json(const Stats& s, double scale) {
  return {{"min", s.min * scale}, {"max", s.max * scale}, {"mean", s.mean * scale},
          {"stddev", s.stddev * scale}, {"count", s.count}};
}

double relative_error(double value, double exact) { return (value - exact) / exact; }

/// Prints and returns the per-group summary; analytic values only for generated vessels.
nlohmann::json report_groups(const TetMesh& mesh, const VesselParams* params, std::ostream& out) {
  nlohmann::json groups = nlohmann::json::array();
  out << "groups:\n";
  for (const auto& g : mesh.groups) {
    nlohmann::json j{{"name", g.name}, {"dim", g.dim}, {"tag", g.tag},
                     {"elements", g.elements.size()}, {"nodes", mesh.group_nodes(g).size()}};
    out << "  " << std::left << std::setw(11) << (g.name.empty() ? "(unnamed)" : g.name)
        << std::right << " dim " << g.dim << " tag " << std::setw(2) << g.tag << ": "
        << std::setw(8) << g.elements.size() << (g.dim == 3 ? " tets     " : " triangles");
    double measure = 0.0;
    double exact = 0.0;
    if (g.dim == 2) {
      measure = group_area(mesh, g);
      j["area_mm2"] = measure * 1e6;
      out << "  area " << std::setprecision(6) << measure * 1e6 << " mm²";
      if (params) {
        if (g.name == group_names::inner_wall) exact = analytic_lateral_area(*params, params->inner_radius);
        if (g.name == group_names::outer_wall) exact = analytic_lateral_area(*params, params->outer_radius());
        if (g.name == group_names::inlet || g.name == group_names::outlet) exact = analytic_end_area(*params);
      }
    } else {
      for (int e : g.elements) {
        const auto& t = mesh.tets[e];
        measure += signed_volume(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]);
      }
      j["volume_mm3"] = measure * 1e9;
      out << "  volume " << std::setprecision(6) << measure * 1e9 << " mm³";
      if (params) exact = analytic_wall_volume(*params);
    }
    if (exact > 0) {
      const double rel = relative_error(measure, exact);
      j["analytic"] = exact * (g.dim == 2 ? 1e6 : 1e9);
      j["relative_error"] = rel;
      out << " (closed form " << exact * (g.dim == 2 ? 1e6 : 1e9) << ", error "
          << std::setprecision(3) << rel * 100 << " %)";
    }
    out << "\n";
    groups.push_back(j);
  }
  return groups;
}

void run_stl_input(const MeshCommandOptions& o) {
  const TriangleSurface s = read_stl(o.input);
  std::vector<Triangle> tris = s.triangles;
  const SurfaceTopology topo = surface_topology(tris);
  std::cout << "surface " << o.input.string() << ": " << s.nodes.size() << " nodes, "
            << s.triangles.size() << " triangles, area " << surface_area(s) * 1e6 << " mm²\n"
            << "  open (boundary) edges " << topo.boundary_edges << ", non-manifold edges "
            << topo.non_manifold_edges << ", inconsistently oriented edges "
            << topo.inconsistent_edges << "\n";
  if (!o.stl.empty()) write_stl(o.stl, s);
}

/// The mesh with each tet's radius ratio and smallest dihedral angle, for ParaView.
void write_quality_vtu(const fs::path& path, const TetMesh& mesh) {
  VtuField ratio{"radius_ratio", 1, {}};
  VtuField dihedral{"min_dihedral_deg", 1, {}};
  for (const auto& t : mesh.tets) {
    const auto tq =
        tet_quality(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]);
    ratio.values.push_back(tq.radius_ratio);
    dihedral.values.push_back(tq.min_dihedral_deg);
  }
  write_vtu(path, mesh, {}, {ratio, dihedral});
  std::cout << "wrote " << path.string() << " (VTU with per-tet quality)\n";
}

void run(MeshCommandOptions& o) {
  if (!o.input.empty() && (o.input.extension() == ".stl" || o.input.extension() == ".STL")) {
    run_stl_input(o);
    return;
  }
  TetMesh mesh;
  MeshSource source;
  VesselParams params;
  const bool generated = o.input.empty();
  if (generated) {
    mesh = mesh_vessel(o.vessel, std::cout, &source);
    params = o.vessel.params;
  } else {
    std::cout << "reading " << o.input.string() << " ...\n";
    mesh = read_msh(o.input);
    require_vessel_groups(mesh, o.input.string());
  }
  std::cout << "mesh: " << mesh.nodes.size() << " nodes, " << mesh.tets.size() << " tets, "
            << mesh.triangles.size() << " boundary triangles\n";
  if (generated && params.style == MeshStyle::structured) {
    const auto c = structured_counts(params);
    std::cout << "  structured grid " << c.circumferential << " circumferential × " << c.axial
              << " axial × " << c.radial << " radial divisions\n";
  }
  nlohmann::json ends = nlohmann::json::array();
  if (generated && params.kind == VesselKind::lumen) {
    const auto named = lumen_file_ends(params.file, params.file_scale, params.listed_ends);
    std::cout << "ends of the lumen: " << named.size() << "\n";
    for (const auto& [group, e] : named) {
      std::cout << "  " << std::left << std::setw(7) << group << std::right << format_end(e)
                << "\n";
      ends.push_back(lumen_end_json(group, e));
    }
  }
  // Closed forms exist for the parametric vessels only (not for a --lumen wall).
  nlohmann::json groups =
      report_groups(mesh, generated && params.parametric() ? &params : nullptr, std::cout);

  std::vector<Triangle> wall_surface;
  for (const auto& name : {group_names::inlet, group_names::outlet, group_names::inner_wall,
                           group_names::outer_wall}) {
    const auto t = mesh.group_triangles(mesh.require_group(name, 2, "mesh"));
    wall_surface.insert(wall_surface.end(), t.begin(), t.end());
  }
  const SurfaceTopology topo = surface_topology(wall_surface);
  std::cout << "boundary surface: "
            << (topo.closed_and_oriented() ? "closed and consistently oriented"
                                           : "NOT closed or not consistently oriented")
            << " (open edges " << topo.boundary_edges << ", inconsistent " << topo.inconsistent_edges
            << ")\n";
  const MeshQuality q = compute_quality(mesh);
  std::cout << "quality:\n" << format_quality(q);
  const SliverReport slivers = find_slivers(mesh);
  if (slivers.count > 0) std::cout << sliver_warning(slivers) << "\n";

  if (!o.output.empty()) {
    write_msh(o.output, mesh, o.msh_version == "2.2" ? MshVersion::v22 : MshVersion::v41);
    std::cout << "wrote " << o.output.string() << " (msh " << o.msh_version << ")\n";
  }
  if (!o.vtu.empty()) write_quality_vtu(o.vtu, mesh);
  if (!o.stl.empty()) {
    write_stl(o.stl, extract_surface(mesh, {o.stl_group}, "mesh"));
    std::cout << "wrote " << o.stl.string() << " (" << o.stl_group << " surface)\n";
  }
  if (!o.stats_json.empty()) {
    nlohmann::json j{{"schema", "vesselverify.mesh_stats"},
                     {"schema_version", 1},
                     {"units", {{"length", "mm"}, {"area", "mm^2"}, {"volume", "mm^3"}, {"angle", "deg"}}},
                     {"source", generated ? describe(params) : o.input.string()},
                     {"nodes", mesh.nodes.size()},
                     {"tets", mesh.tets.size()},
                     {"triangles", mesh.triangles.size()},
                     {"groups", groups},
                     {"boundary_closed_and_oriented", topo.closed_and_oriented()},
                     {"quality",
                      {{"dihedral_deg", stats_to_json(q.dihedral_deg, 1.0)},
                       {"radius_ratio", stats_to_json(q.radius_ratio, 1.0)},
                       {"edge_length_mm", stats_to_json(q.edge_length, 1e3)},
                       {"tet_volume_mm3", stats_to_json(q.volume, 1e9)},
                       {"inverted", q.inverted},
                       {"degenerate", q.degenerate}}}};
    j["mesh_quality"] = mesh_quality_json(slivers);
    if (!ends.empty()) j["lumen_ends"] = ends;
    if (generated) {
      j["meshing"] = {{"seconds", source.seconds}, {"cache_hit", source.cache_hit},
                      {"cached_file", source.path.string()}};
    }
    write_file_atomically(o.stats_json, [&](std::ostream& out) { out << j.dump(2) << "\n"; });
    std::cout << "wrote " << o.stats_json.string() << "\n";
  }
}

}  // namespace

void add_mesh_command(CLI::App& app) {
  auto options = std::make_shared<MeshCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "mesh",
      "Generate a vessel mesh with gmsh (or read a .msh/.stl), print node, element and group "
      "counts, volumes and areas against their closed forms, and tet quality; optionally write "
      ".msh, VTU, STL and a JSON summary.\n"
      "Examples:\n"
      "  vesselverify mesh                              # default straight tube, level 0\n"
      "  vesselverify mesh --vessel arch --level 1 -o arch.msh --vtu arch.vtu\n"
      "  vesselverify mesh --structured --level 2\n"
      "  vesselverify mesh --input my_vessel.msh        # check a user mesh");
  add_vessel_options(*cmd, options->vessel);
  cmd->add_option("--input", options->input,
                  "Read this .msh (2.2 or 4.1 ASCII, with groups inlet, outlet, inner_wall, "
                  "outer_wall, wall) or .stl instead of generating");
  cmd->add_option("-o,--output", options->output, "Write the mesh to this .msh file");
  cmd->add_option("--msh-version", options->msh_version, ".msh format version to write")
      ->check(CLI::IsMember({"2.2", "4.1"}))
      ->capture_default_str();
  cmd->add_option("--vtu", options->vtu, "Write a VTU (ParaView) file with per-tet quality");
  cmd->add_option("--stl", options->stl, "Write one surface group as binary STL");
  cmd->add_option("--stl-group", options->stl_group, "Surface group written by --stl")
      ->capture_default_str();
  cmd->add_option("--stats-json", options->stats_json, "Write the statistics as JSON");
  cmd->callback([options] { run(*options); });
}

}  // namespace vessel::cli
