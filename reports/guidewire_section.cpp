#include "reports/guidewire_section.hpp"

namespace vessel::reports {

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
                "patch. With compliant coupling each wall gives way by its own compliance, so "
                "each model gets its own force (docs/rods.md), and its field error is given at the "
                "rigid wire's force (both walls under the same load) and with each wall under its "
                "own coupled force. ⚠: the wire's contact slid out of the load's patch, outside "
                "the coupling's validity.");
  doc.table(rigid);
  if (g.coupled.empty()) return;
  Table coupled;
  coupled.header = {"model", "ν", "level", "EI N·m²", "force mN", "reference mN", "error mN",
                    "contact displ. mm", "reference mm", "slide mm", "field rel. L2, rigid force",
                    "field rel. L2, coupled"};
  const auto optional = [](const std::optional<double>& v) { return v ? significant(*v) : "–"; };
  for (const GuidewireCoupledRow& r : g.coupled) {
    std::vector<std::string> row{r.model, significant(r.poisson_ratio), std::to_string(r.level),
                                 significant(r.bending_stiffness)};
    if (!r.ok) {
      row.push_back("failed: " + r.failure);
      row.resize(coupled.header.size(), "");
    } else {
      row.insert(row.end(), {significant(r.force_mN), significant(r.reference_force_mN),
                             significant(r.force_mN - r.reference_force_mN),
                             significant(r.displacement_mm),
                             significant(r.reference_displacement_mm),
                             significant(r.slide_mm) + (r.within_patch ? "" : " ⚠"),
                             optional(r.field_relative_l2_rigid), optional(r.field_relative_l2)});
    }
    coupled.rows.push_back(std::move(row));
  }
  doc.table(coupled);
}

}  // namespace vessel::reports
