#include "reports/insertion_section.hpp"

#include <optional>
#include <sstream>

namespace vessel::reports {

namespace {

std::string stiffness_label(double EI) {
  std::ostringstream s;
  s << "EI " << EI << " N·m²";
  return s.str();
}

Table insertion_table(const InsertionEntry& e) {
  Table t;
  t.header = {"insertion (mm)",
              "force (mN)",
              "pressed",
              "zones (centroid z mm: mN)",
              "dent (mm)",
              "clamp axial R·t (mN)",
              "push R·t − M²/2EI (mN)",
              "push dΠ/dL (mN)",
              "tip (mm)",
              "Newton steps",
              "s"};
  for (const InsertionStepEntry& s : e.steps) {
    if (!s.converged) {
      std::vector<std::string> row(t.header.size());
      row[0] = decimals(s.insertion * 1e3, 3);
      row[1] = "not converged: " + s.failure;
      row[10] = decimals(s.seconds, 1);  // Newton steps: the failed solve's are in its message
      t.rows.push_back(row);
      continue;
    }
    std::string zones;
    for (const InsertionZoneEntry& z : s.zones) {
      zones += (zones.empty() ? "" : "; ") + decimals(z.centroid[2] * 1e3, 2) + ": " +
               decimals(z.force * 1e3, 4);
    }
    t.rows.push_back({decimals(s.insertion * 1e3, 3), decimals(s.force * 1e3, 5),
                      std::to_string(s.pressed), zones, decimals(s.dent * 1e3, 3),
                      decimals(s.clamp_axial * 1e3, 5), decimals(s.push * 1e3, 5),
                      s.push_by_energy ? decimals(*s.push_by_energy * 1e3, 5) : "—",
                      "(" + decimals(s.tip[0] * 1e3, 2) + ", " + decimals(s.tip[1] * 1e3, 2) + ", " +
                          decimals(s.tip[2] * 1e3, 2) + ")",
                      std::to_string(s.newton_steps), decimals(s.seconds, 1)});
  }
  return t;
}

/// The section without its figure: the text, and a heading, a line and a table per insertion.
void insertion_text(Document& doc, const InsertionFile& f) {
  doc.heading(2, "The guidewire pushed in");
  doc.paragraph(
      "The scene's wire (DER) pushed into the vessel in steps, quasi-statically, against the "
      "deformable wall: at each insertion length the wire and the wall are solved together as "
      "one potential from the last step's equilibrium, so contacts appear, slide and separate as "
      "the solve finds them (the wall meshed once, refined where the wire touches the rigid "
      "lumen over the range). Each wall on the same mesh: the reference (deal.II's FEM) or a "
      "vessel model's own (its own energy, so its own equilibrium). *force* is the wire's net "
      "force on the wall, |Σ λ_j n_j|; a zone "
      "is a group of pressed wall nodes closer than 1 mm to each other (its force-weighted "
      "centroid along the axis and its force); *dent* the largest displacement of a pressed "
      "node. The hub: the clamp's axial force R·t, and the push that advances the wire, "
      "R·t − M²/2EI (a rod leaving a frictionless sleeve is drawn out of it by M²/2EI: Bigoni "
      "et al. 2015), checked against dΠ/dL, the stored energy's derivative along the insertion "
      "by central differences of the neighbouring steps. Made by `" +
      f.command + "` in " + significant(f.total_seconds, 3) + " s.");
  for (const InsertionEntry& e : f.insertions) {
    doc.heading(3, e.scene + ", " + e.model + ", " + stiffness_label(e.bending_stiffness));
    doc.paragraph(e.model_detail + "; " + std::to_string(e.mesh_nodes) + " nodes, refined at " +
                  std::to_string(e.refined_balls) + " rigid-lumen wall point(s); set-up " +
                  decimals(e.mesh_seconds, 1) + " s" +
                  (e.cached_from.empty() ? std::string(".")
                                         : "; read from the cache, computed " + e.cached_from +
                                               " (the times are that run's)."));
    doc.table(insertion_table(e));
  }
}

}  // namespace

Plot insertion_plot(const InsertionFile& f) {
  Plot plot;
  plot.title = "The insertion: forces against the insertion length";
  plot.x.label = "insertion length (mm)";
  plot.y.label = "force (mN)";
  for (const InsertionEntry& e : f.insertions) {
    const std::string ei = " (" + e.model + ", " + stiffness_label(e.bending_stiffness) + ")";
    const auto series = [&](const std::string& name, auto value, bool dashed) {
      Series s;
      s.label = name + ei;
      s.lines = true;
      s.dashed = dashed;
      for (const InsertionStepEntry& step : e.steps) {
        if (!step.converged) continue;
        const std::optional<double> y = value(step);
        if (!y) continue;
        s.x.push_back(step.insertion * 1e3);
        s.y.push_back(*y * 1e3);
      }
      plot.series.push_back(std::move(s));
    };
    using Step = InsertionStepEntry;
    series(
        "contact force", [](const Step& s) { return std::optional(s.force); }, false);
    series(
        "clamp axial R·t", [](const Step& s) { return std::optional(s.clamp_axial); }, false);
    series(
        "push R·t − M²/2EI", [](const Step& s) { return std::optional(s.push); }, false);
    series(
        "push dΠ/dL", [](const Step& s) { return s.push_by_energy; }, true);
  }
  return plot;
}

void insertion_section(Document& doc, const InsertionFile& f) {
  insertion_text(doc, f);
  doc.figure("insertion.svg", insertion_plot(f),
             "The contact force and the hub's forces against the insertion length, per wall and wire "
             "stiffness (converged steps).");
}

std::string insertion_markdown(const InsertionFile& f) {
  Document doc;
  insertion_text(doc, f);
  return doc.markdown_text("figures");
}

}  // namespace vessel::reports
