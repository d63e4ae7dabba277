#include "reports/guidewire_section.hpp"

namespace vessel::reports {

namespace {

std::string optional_number(const std::optional<double>& v) { return v ? significant(*v) : "–"; }

/// One EI's walls in the contact solve against the reference's.
Table contact_wall_table(const ContactRun& run) {
  Table t;
  t.header = {"model",   "force mN",     "error %",  "pressed", "zone along × around mm",
              "dent mm", "tip error mm", "set-up s", "solve s"};
  for (const ContactWallRow& m : run.models) {
    if (!m.ok) {
      std::vector<std::string> row{m.model, "failed: " + m.failure};
      row.resize(t.header.size(), "");
      t.rows.push_back(std::move(row));
      continue;
    }
    t.rows.push_back(
        {m.model, significant(m.force_mN, 4), optional_number(m.force_error_percent),
         std::to_string(m.pressed),
         significant(m.axial_extent_mm) + " × " + significant(m.circumferential_extent_mm),
         significant(m.dent_mm), optional_number(m.tip_error_mm), significant(m.setup_seconds),
         significant(m.solve_seconds)});
  }
  return t;
}

/// The contact solve's tables: per EI the models against the reference, then the shortcuts.
void contact_tables(Document& doc, const GuidewireContactRows& c) {
  doc.paragraph(
      "The wire–wall contact (coupling = \"contact\"): the wire's surface against each "
      "model's wall " +
      std::string(c.wall == "neo-Hookean"
                      ? "at its own nonlinear equilibrium (the reference the neo-Hookean FEM wall)"
                      : "linearised at rest") +
      ", the contact zone found by the solve (no patch), every wall on one mesh of " +
      std::to_string(c.mesh_nodes) + " nodes refined to " + significant(c.fine_size_mm) +
      " mm within " + significant(c.fine_radius_mm) +
      " mm of the rigid wire's contact, at ν = " + significant(c.poisson_ratio) +
      "; each force against the FEM P" + std::to_string(c.reference_degree) +
      " wall's in the same solve. The shortcuts are the forces a simulator takes "
      "instead: the rigid lumen's, and the series springs above.");
  for (const ContactRun& run : c.runs) {
    const ContactWallRow& ref = run.reference;
    std::string line = "EI " + significant(run.bending_stiffness) + " N·m²: the reference ";
    if (!ref.ok) {
      doc.paragraph(line + "failed (" + ref.failure + "), so no model is judged.");
      continue;
    }
    line += significant(ref.force_mN, 4) + " mN (rigid lumen " +
            significant(run.rigid_force_mN, 4) + " mN), dent " + significant(ref.dent_mm) +
            " mm, largest strain " + significant(ref.largest_strain) + ".";
    if (c.wall == "linear" && !run.within_linear_validity) {  // neo-Hookean: no strain limit
      line += " ⚠ Beyond the linear reference's validity (largest strain above " +
              significant(c.strain_limit) +
              "): these rows show the regime, not a prediction; the finite-strain reference is "
              "`vesselverify contact-models --own-equilibrium`.";
    }
    doc.paragraph(line);
    doc.table(contact_wall_table(run));
    Table s;
    s.header = {"shortcut", "force mN", "error %"};
    for (const ContactShortcutRow& r : run.shortcuts) {
      s.rows.push_back(
          {r.name, significant(r.force_mN, 4), optional_number(r.force_error_percent)});
    }
    doc.table(s);
  }
}

void coupled_table(Document& doc, const GuidewireRows& g) {
  Table coupled;
  coupled.header = {"model",
                    "ν",
                    "level",
                    "EI N·m²",
                    "force mN",
                    "reference mN",
                    "error mN",
                    "contact displ. mm",
                    "reference mm",
                    "slide mm",
                    "field rel. L2, rigid force",
                    "field rel. L2, coupled"};
  for (const GuidewireCoupledRow& r : g.coupled) {
    std::vector<std::string> row{r.model, significant(r.poisson_ratio), std::to_string(r.level),
                                 significant(r.bending_stiffness)};
    if (!r.ok) {
      row.push_back("failed: " + r.failure);
      row.resize(coupled.header.size(), "");
    } else {
      row.insert(
          row.end(),
          {significant(r.force_mN), significant(r.reference_force_mN),
           significant(r.force_mN - r.reference_force_mN), significant(r.displacement_mm),
           significant(r.reference_displacement_mm) + (r.reference_within_wall ? "" : " ✗"),
           significant(r.slide_mm) + (r.within_patch ? "" : " ⚠"),
           optional_number(r.field_relative_l2_rigid), optional_number(r.field_relative_l2)});
    }
    coupled.rows.push_back(std::move(row));
  }
  doc.table(coupled);
}

}  // namespace

void guidewire_section(Document& doc, const SceneRows& s) {
  if (!s.guidewire) return;
  const GuidewireRows& g = *s.guidewire;
  doc.heading(3, "The guidewire");
  Table rigid;
  rigid.header = {"EI N·m²", "force against the rigid lumen mN", "wire compliance m/N"};
  for (const GuidewireRigidRow& r : g.rigid) {
    rigid.rows.push_back({significant(r.bending_stiffness), significant(r.force_mN),
                          r.wire_compliance ? significant(*r.wire_compliance) : "–"});
  }
  doc.paragraph("The wire (" + g.model + ", coupling " + g.coupling +
                ") against the rigid lumen: its contact force loads every model as the contact "
                "patch. With compliant or contact coupling (the series springs) each wall gives "
                "way by its own compliance, so "
                "each model gets its own force (docs/rods.md), and its field error is given at the "
                "rigid wire's force (both walls under the same load) and with each wall under its "
                "own coupled force. ⚠: the wire's contact slid out of the load's patch, outside "
                "the coupling's validity. ✗: the series springs dent the reference's wall deeper "
                "than it is thick: no linear wall holds the wire there, and the row's figures are "
                "the springs' arithmetic, not a state of the vessel.");
  doc.table(rigid);
  if (!g.coupled.empty()) coupled_table(doc, g);
  if (g.contact) contact_tables(doc, *g.contact);
}

}  // namespace vessel::reports
