#include "verification/harness/guidewire_coupling.hpp"

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "msm/rods/rod_layout.hpp"
#include "verification/guidewire/guidewire_load.hpp"

namespace vessel {

namespace {

/// The relative L2 error of r·u against u_ref, from e = |u − u_ref|/|u_ref| and
/// a = |u|/|u_ref| (the same nodes): |r u − u_ref|²/|u_ref|² = r²a² − r(a² + 1 − e²) + 1, the
/// inner product ⟨u, u_ref⟩/|u_ref|² = (a² + 1 − e²)/2 read off |u − u_ref|².
double scaled_relative_l2(double r, double e, double a) {
  return std::sqrt(std::max(0.0, r * r * a * a - r * (a * a + 1.0 - e * e) + 1.0));
}

/// Outcomes a compliance can be read from: solved, static, with an indentation under a load.
bool couplable(const ModelOutcome& o) {
  return o.ok && o.magnitude > 0.0 && o.quantities.indentation_mm &&
         o.quantities.indentation_reference_mm && o.history.time_s.empty();
}

/// The reference's coupled wire of one EI from its rows (from `first`): the finest level's first
/// ok row at the first row's ν, whose walls report.html draws.
void set_reference_wire(const std::vector<GuidewireCouplingRow>& rows, std::size_t first,
                        const std::vector<std::vector<Vec3>>& lines, GuidewireRigid& rigid) {
  std::optional<std::size_t> chosen;
  for (std::size_t k = first; k < rows.size(); ++k) {
    const GuidewireCouplingRow& r = rows[k];
    if (!r.ok || r.poisson_ratio != rows[first].poisson_ratio) continue;
    if (!chosen || r.level > rows[*chosen].level) chosen = k;
  }
  if (!chosen || *chosen - first >= lines.size()) return;
  const GuidewireCouplingRow& r = rows[*chosen];
  rigid.reference_centreline = lines[*chosen - first];
  rigid.reference_force = r.reference_force_mN * 1e-3;
  rigid.reference_compliance = r.reference_compliance;
  std::ostringstream what;
  what << r.model << ", ν " << r.poisson_ratio << ", level " << r.level;
  rigid.reference_row = what.str();
}

void couple_at(const Scene& s, double EI, const std::vector<ModelOutcome>& outcomes,
               GuidewireOutcome& g) {
  const GuidewireSpec spec = with_stiffness(*s.load.guidewire, EI);
  GuidewireSolver solver(s.vessel, spec);
  GuidewireRigid rigid;
  rigid.bending_stiffness = EI;
  rigid.solution = solver.solve_rigid();
  std::string why;
  if (const auto c = continuum_wire(s.vessel, spec, why)) rigid.continuum_force = c->force;
  if (spec.coupling != GuidewireCoupling::rigid && rigid.solution.force > 0.0) {
    rigid.wire_compliance = solver.compliance();
  }
  if (spec.coupling == GuidewireCoupling::rigid) {
    g.rigid.push_back(rigid);
    return;
  }
  const std::size_t first_row = g.rows.size();
  std::vector<std::vector<Vec3>> reference_lines;  // per row of this EI: the reference's wire
  for (const ModelOutcome& o : outcomes) {
    if (!couplable(o)) continue;
    GuidewireCouplingRow row;
    row.model = o.model;
    row.poisson_ratio = o.poisson_ratio;
    row.level = o.level;
    row.bending_stiffness = EI;
    row.wall_compliance = *o.quantities.indentation_mm * 1e-3 / o.magnitude;
    row.reference_compliance = *o.quantities.indentation_reference_mm * 1e-3 / o.magnitude;
    try {
      const double F = solver.coupled_force(row.wall_compliance);
      row.contact_point = solver.last().contact_point;
      const double Fref = solver.coupled_force(row.reference_compliance);
      reference_lines.resize(g.rows.size() - first_row + 1);
      reference_lines.back() = solver.last().centreline;
      row.force_mN = F * 1e3;
      row.reference_force_mN = Fref * 1e3;
      row.displacement_mm = row.wall_compliance * F * 1e3;
      row.reference_displacement_mm = row.reference_compliance * Fref * 1e3;
      if (o.error.model_l2_over_reference > 0.0) {
        row.field_relative_l2_rigid = o.error.relative_l2;
        row.field_relative_l2 =
            scaled_relative_l2(F / Fref, o.error.relative_l2, o.error.model_l2_over_reference);
      }
      row.ok = true;
    } catch (const std::exception& e) {
      row.failure = e.what();
    }
    g.rows.push_back(row);
  }
  set_reference_wire(g.rows, first_row, reference_lines, rigid);
  g.rigid.push_back(rigid);
}

/// How far the wire's contact node slid along the wall from the rigid solve's, mm (the patch
/// stays at the rigid one's).
double slide_mm(const GuidewireOutcome& g, const GuidewireCouplingRow& r) {
  for (const GuidewireRigid& rigid : g.rigid) {
    if (rigid.bending_stiffness == r.bending_stiffness) {
      const Vec3 d = r.contact_point - rigid.solution.contact_point;
      return (d - d.dot(rigid.solution.normal) * rigid.solution.normal).norm() * 1e3;
    }
  }
  return std::numeric_limits<double>::quiet_NaN();
}

/// reference_within_wall at the row's EI.
bool row_within_wall(const GuidewireOutcome& g, const GuidewireCouplingRow& r) {
  for (const GuidewireRigid& rigid : g.rigid) {
    if (rigid.bending_stiffness == r.bending_stiffness) {
      return reference_within_wall(rigid, g.wall_thickness);
    }
  }
  return true;
}

nlohmann::json finite_or_null(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
}

nlohmann::json vec_mm(const Vec3& p) { return {p.x() * 1e3, p.y() * 1e3, p.z() * 1e3}; }

/// The wire coupled with the reference's wall at one EI (null without one).
nlohmann::json reference_wire_json(const GuidewireRigid& r) {
  if (r.reference_centreline.empty()) return nullptr;
  nlohmann::json line = nlohmann::json::array();
  for (const Vec3& p : r.reference_centreline) line.push_back(vec_mm(p));
  return {{"row", r.reference_row},
          {"wall_compliance_m_per_N", r.reference_compliance},
          {"contact_force_N", r.reference_force},
          {"centreline_mm", line}};
}

}  // namespace

bool reference_within_wall(const GuidewireRigid& rigid, double wall_thickness) {
  return !(rigid.reference_compliance * rigid.reference_force > wall_thickness);
}

GuidewireOutcome couple_guidewire(const Scene& s, const std::vector<ModelOutcome>& outcomes) {
  if (!s.load.wire) {
    throw std::logic_error("couple_guidewire: the scene's guidewire is not solved yet "
                           "(solve_guidewire_load)");
  }
  GuidewireOutcome g;
  g.spec = *s.load.guidewire;
  g.patch_radius = s.load.contact.radius;
  g.wall_thickness = s.vessel.wall_thickness;
  for (const double EI : guidewire_stiffnesses(g.spec)) couple_at(s, EI, outcomes, g);
  return g;
}

std::vector<double> guidewire_stiffnesses(const GuidewireSpec& spec) {
  const double own =
      msm::rods::solid_section({spec.young, spec.shear, spec.density}, spec.diameter).EI;
  std::vector<double> out{own};
  for (const double EI : spec.stiffness_sweep) {
    if (std::abs(EI / own - 1.0) > 1e-3) out.push_back(EI);
  }
  return out;
}

void write_guidewire_markdown(std::ostream& out, const GuidewireOutcome& g) {
  const bool compliant = g.spec.coupling != GuidewireCoupling::rigid;
  out << "Guidewire (" << to_string(g.spec.model) << ", " << g.spec.segments << " segments, d = "
      << g.spec.diameter * 1e3 << " mm, insertion " << g.spec.insertion * 1e3
      << " mm): against the rigid lumen, its force loads every model above"
      << (compliant ? "; coupled, each wall gives way by its compliance C (its indentation per "
                      "unit patch force, measured at that load; linear walls)"
                    : "")
      << ".\n\n| EI N·m² | rigid force mN | contact point mm | wire compliance m/N |\n"
         "|---|---|---|---|\n";
  for (const GuidewireRigid& r : g.rigid) {
    const Vec3& p = r.solution.contact_point;
    out << "| " << r.bending_stiffness << " | " << r.solution.force * 1e3 << " | (" << p.x() * 1e3
        << ", " << p.y() * 1e3 << ", " << p.z() * 1e3 << ") | "
        << (compliant ? "" : "–");
    if (compliant) out << r.wire_compliance;
    out << " |\n";
  }
  out << "\n";
  if (g.rows.empty()) return;
  out << "The lumen gives way as a whole, so the wire's contact node slides along the wall (slide); "
         "⚠: it left the load's patch (radius "
      << g.patch_radius * 1e3
      << " mm), and the row is outside the coupling's validity. ✗: the series springs dent the "
         "reference's wall deeper than it is thick ("
      << g.wall_thickness * 1e3
      << " mm): no linear wall holds the wire there, so the row's figures are the springs' "
         "arithmetic, not a state of the vessel (the finite-strain contact: contact_wall = "
         "\"neo-hookean\" in the scene, or vesselverify contact-models --own-equilibrium).\n\n";
  out << "| model | ν | level | EI N·m² | C m/N | C_ref m/N | force mN | reference mN | error mN | "
         "contact displ. mm | reference mm | error mm | slide mm | field rel. L2 rigid | "
         "field rel. L2 coupled |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const GuidewireCouplingRow& r : g.rows) {
    out << "| " << r.model << " | " << r.poisson_ratio << " | " << r.level << " | "
        << r.bending_stiffness << " | ";
    if (!r.ok) {
      out << "FAILED: " << r.failure << " | | | | | | | | | | |\n";
      continue;
    }
    out << r.wall_compliance << " | " << r.reference_compliance << " | " << r.force_mN << " | "
        << r.reference_force_mN << " | " << r.force_mN - r.reference_force_mN << " | "
        << r.displacement_mm << " | " << r.reference_displacement_mm
        << (row_within_wall(g, r) ? "" : " ✗") << " | "
        << r.displacement_mm - r.reference_displacement_mm << " | " << slide_mm(g, r)
        << (slide_mm(g, r) > g.patch_radius * 1e3 ? " ⚠" : "") << " | " << r.field_relative_l2_rigid
        << " | " << r.field_relative_l2 << " |\n";
  }
  out << "\n";
}

nlohmann::json guidewire_json(const GuidewireOutcome& g) {
  const GuidewireSpec& w = g.spec;
  nlohmann::json rigid = nlohmann::json::array();
  for (const GuidewireRigid& r : g.rigid) {
    const GuidewireSolution& s = r.solution;
    nlohmann::json line = nlohmann::json::array();
    for (const Vec3& p : s.centreline) line.push_back(vec_mm(p));
    rigid.push_back({{"bending_stiffness_Nm2", r.bending_stiffness},
                     {"contact_force_N", s.force},
                     {"contact_point_mm", vec_mm(s.contact_point)},
                     {"wall_point_mm", vec_mm(s.wall_point)},
                     {"normal", {s.normal.x(), s.normal.y(), s.normal.z()}},
                     {"clamp_force_N", {s.clamp_force.x(), s.clamp_force.y(), s.clamp_force.z()}},
                     {"wire_compliance_m_per_N", r.wire_compliance},
                     {"centreline_mm", line},
                     {"continuum_force_N", finite_or_null(r.continuum_force)},
                     {"force_error_mN", finite_or_null(std::abs(s.force - r.continuum_force) * 1e3)},
                     {"reference_coupled", reference_wire_json(r)}});
  }
  nlohmann::json rows = nlohmann::json::array();
  for (const GuidewireCouplingRow& r : g.rows) {
    rows.push_back({{"model", r.model},
                    {"poisson_ratio", r.poisson_ratio},
                    {"level", r.level},
                    {"bending_stiffness_Nm2", r.bending_stiffness},
                    {"wall_compliance_m_per_N", r.wall_compliance},
                    {"reference_compliance_m_per_N", r.reference_compliance},
                    {"force_mN", r.force_mN},
                    {"reference_force_mN", r.reference_force_mN},
                    {"force_error_mN", r.force_mN - r.reference_force_mN},
                    {"contact_displacement_mm", r.displacement_mm},
                    {"reference_contact_displacement_mm", r.reference_displacement_mm},
                    {"contact_point_mm", vec_mm(r.contact_point)},
                    {"slide_mm", slide_mm(g, r)},
                    {"within_patch", slide_mm(g, r) <= g.patch_radius * 1e3},
                    {"reference_within_wall", row_within_wall(g, r)},
                    {"contact_displacement_error_mm", r.displacement_mm - r.reference_displacement_mm},
                    {"field_relative_l2_rigid", finite_or_null(r.field_relative_l2_rigid)},
                    {"field_relative_l2", finite_or_null(r.field_relative_l2)},
                    {"ok", r.ok},
                    {"failure", r.failure}});
  }
  return {
      {"model", to_string(w.model)},
      {"coupling", to_string(w.coupling)},
      {"young_pa", w.young},
      {"shear_pa", w.shear},
      {"diameter_m", w.diameter},
      {"insertion_m", w.insertion},
      {"segments", w.segments},
      {"clamp_point_mm", vec_mm(w.clamp_point)},
      {"clamp_direction", {w.clamp_direction.x(), w.clamp_direction.y(), w.clamp_direction.z()}},
      {"patch_radius_m", g.patch_radius},
      {"rigid", rigid},
      {"coupling_rows", rows}};
}

}  // namespace vessel
