#pragma once
/// The guidewire's insertion in the report (read from `vesselverify insertion --json`,
/// reports/study_files.hpp): per wire stiffness, each step's contact force, zones, dent, the
/// hub's forces and the tip as a table, and the forces against the insertion length as curves
/// (verification/harness/contact_insertion.hpp computes them; docs/physics/contact.md explains
/// them).
#include <string>
#include <vector>

#include "reports/document.hpp"
#include "reports/study_files.hpp"
#include "reports/svg_plot.hpp"
#include "reports/web_page.hpp"

namespace vessel::reports {

/// "## The guidewire pushed in": how the insertion was made, then per insertion its table and
/// the curves of every insertion in one figure.
void insertion_section(Document& doc, const InsertionFile& insertion);

/// Per scene with an insertion's view, report.html's 3D view of the wall near the wire at the
/// step its document chose (the last converged one, or the one nearest --view-at; scene
/// "insertion-<scene>", filling the section's slot): each insertion's
/// wall at true scale, coloured by the wire's contact force per node (mN); the ghost the
/// reference's wall at the same nodes (at rest where the file has no reference at that step);
/// the wire on the first wall drawn, its part within 2 mm of that wall.
std::vector<SceneViews> insertion_views(const InsertionFile& insertion);

/// The section alone as Markdown (what `vesselverify insertion` prints; no figure).
std::string insertion_markdown(const InsertionFile& insertion);

/// The insertions' curves against the insertion length (mm, mN), per insertion: the total
/// contact force, the clamp's axial force R·t, the push R·t − M²/2EI and the push dΠ/dL (dashed;
/// its undefined ends left out). Converged steps only.
Plot insertion_plot(const InsertionFile& insertion);

}  // namespace vessel::reports
