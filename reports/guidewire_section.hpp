#pragma once
/// A guidewire scene's wire in the report: its contact force against the rigid lumen at each
/// bending stiffness, and each model's coupled contact force against the reference's
/// (verification/harness/guidewire_coupling.hpp computes them; docs/rods.md explains them).
#include "reports/document.hpp"
#include "reports/results_file.hpp"

namespace vessel::reports {

/// Nothing when the scene has no guidewire load.
void guidewire_section(Document& doc, const SceneRows& scene);

}  // namespace vessel::reports
