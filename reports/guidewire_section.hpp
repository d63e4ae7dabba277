#pragma once
/// A guidewire scene's wire in the report: its contact force against the rigid lumen at each
/// bending stiffness, each model's coupled contact force against the reference's
/// (verification/harness/guidewire_coupling.hpp computes them; docs/rods.md explains them) and,
/// with coupling = "contact", each model's force, zone and dent in the wire–wall contact solve
/// beside the reference's, and the shortcuts' forces against it
/// (verification/harness/guidewire_contact.hpp; docs/physics/contact.md).
#include "reports/document.hpp"
#include "reports/results_file.hpp"

namespace vessel::reports {

/// Nothing when the scene has no guidewire load.
void guidewire_section(Document& doc, const SceneRows& scene);

}  // namespace vessel::reports
