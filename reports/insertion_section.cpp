#include "reports/insertion_section.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>
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

/// Each model's insertion against the reference's of the same scene and EI, step by step at the
/// lengths both solved: the contact force and its error, the dent and the tip's distance from
/// the reference's. Empty when there is no such pair.
Table models_against_reference(const InsertionFile& f) {
  Table t;
  t.header = {"scene",
              "EI (N·m²)",
              "model",
              "insertion (mm)",
              "force (mN)",
              "reference (mN)",
              "error (mN)",
              "error (%)",
              "dent (mm)",
              "reference dent (mm)",
              "tip from the reference's (mm)",
              "clamp axial R·t (mN)",
              "reference R·t (mN)"};
  for (const InsertionEntry& r : f.insertions) {
    if (r.model != "reference") continue;
    for (const InsertionEntry& m : f.insertions) {
      if (m.model == "reference" || m.scene != r.scene ||
          m.bending_stiffness != r.bending_stiffness) {
        continue;
      }
      for (const InsertionStepEntry& s : m.steps) {
        const auto ref = std::find_if(r.steps.begin(), r.steps.end(), [&](const auto& q) {
          return std::abs(q.insertion - s.insertion) < 1e-9;
        });
        if (ref == r.steps.end()) continue;
        std::vector<std::string> row{r.scene, significant(r.bending_stiffness, 3), m.model,
                                     decimals(s.insertion * 1e3, 3)};
        if (!s.converged || !ref->converged) {
          row.push_back(!s.converged ? "not converged" : decimals(s.force * 1e3, 5));
          row.push_back(!ref->converged ? "not converged" : decimals(ref->force * 1e3, 5));
          row.resize(t.header.size(), "—");
          t.rows.push_back(row);
          continue;
        }
        const double tip_error = std::sqrt(std::pow(s.tip[0] - ref->tip[0], 2) +
                                           std::pow(s.tip[1] - ref->tip[1], 2) +
                                           std::pow(s.tip[2] - ref->tip[2], 2));
        row.insert(row.end(),
                   {decimals(s.force * 1e3, 5), decimals(ref->force * 1e3, 5),
                    decimals((s.force - ref->force) * 1e3, 5),
                    decimals(100.0 * (s.force / ref->force - 1.0), 2), decimals(s.dent * 1e3, 3),
                    decimals(ref->dent * 1e3, 3), decimals(tip_error * 1e3, 3),
                    decimals(s.clamp_axial * 1e3, 5), decimals(ref->clamp_axial * 1e3, 5)});
        t.rows.push_back(row);
      }
    }
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
  const Table against = models_against_reference(f);
  if (!against.rows.empty()) {
    doc.heading(3, "Each model against the reference");
    doc.paragraph(
        "Each model's wall in the same insertion (the same mesh, wire and contact law, its own "
        "equilibrium) against the reference's at the lengths both solved: the wire's net contact "
        "force and its error, the dent, how far the wire's tip is from where it is on the "
        "reference's wall, and the force the clamp holding the wire bears along it (R·t, what the "
        "hand at the hub feels) beside the reference's.");
    doc.table(against);
  }
}

std::string view_scene(const std::string& scene) { return "insertion-" + scene; }

/// The reference's entry with a view at the same EI and insertion length as `e`'s view, if any.
const InsertionEntry* reference_at(const InsertionFile& f, const InsertionEntry& e) {
  const double L = e.steps[static_cast<std::size_t>(e.view->step)].insertion;
  for (const InsertionEntry& r : f.insertions) {
    if (r.model == "reference" && r.scene == e.scene && r.view &&
        r.bending_stiffness == e.bending_stiffness &&
        r.steps[static_cast<std::size_t>(r.view->step)].insertion == L) {
      return &r;
    }
  }
  return nullptr;
}

/// The force-weighted mean direction of the pressed nodes' displacements (the dent's, out of the
/// lumen: the camera looks from there, onto the wall's outside), or none without a force.
std::optional<std::vector<double>> dent_direction(const InsertionViewEntry& v) {
  Vec3 d = Vec3::Zero();
  for (std::size_t k = 0; k < v.force.size(); ++k) {
    d += v.force[k] *
         Vec3(v.displacement[3 * k], v.displacement[3 * k + 1], v.displacement[3 * k + 2]);
  }
  if (!(d.norm() > 0.0)) return std::nullopt;
  d.normalize();
  return std::vector<double>{d.x(), d.y(), d.z()};
}

/// The force-weighted centroid of the view's contact forces on the deformed wall (mm; a red
/// sphere marks it), or none without a force.
std::optional<std::vector<double>> contact_centroid_mm(const InsertionViewEntry& v) {
  double total = 0.0;
  std::vector<double> c(3, 0.0);
  for (std::size_t k = 0; k < v.force.size(); ++k) {
    total += v.force[k];
    for (std::size_t i = 0; i < 3; ++i) {
      c[i] += v.force[k] * (v.rest[3 * k + i] + v.displacement[3 * k + i]) * 1e3;
    }
  }
  if (!(total > 0.0)) return std::nullopt;
  for (double& x : c) x /= total;
  return c;
}

/// Per drawn node the contact pressure (kPa): its force over its share of the inner wall's area at
/// rest, a third of each drawn triangle it is a corner of (the lumped pressure, independent of the
/// mesh's size where a node's force is not). A pressed node lies 2 mm inside the drawn wall's
/// edge, so every triangle it touches is drawn.
std::vector<double> pressure_kPa(const InsertionViewEntry& v) {
  std::vector<double> area(v.nodes.size(), 0.0);
  const auto at = [&](int k) {
    const auto i = 3 * static_cast<std::size_t>(k);
    return Vec3(v.rest[i], v.rest[i + 1], v.rest[i + 2]);
  };
  for (std::size_t t = 0; t + 2 < v.triangles.size(); t += 3) {
    const int a = v.triangles[t], b = v.triangles[t + 1], c = v.triangles[t + 2];
    const double third = (at(b) - at(a)).cross(at(c) - at(a)).norm() / 6.0;
    for (const int k : {a, b, c}) area[static_cast<std::size_t>(k)] += third;
  }
  std::vector<double> out(v.nodes.size(), 0.0);
  for (std::size_t k = 0; k < out.size(); ++k) {
    if (area[k] > 0.0) out[k] = v.force[k] / area[k] * 1e-3;
  }
  return out;
}

WallView insertion_wall(const InsertionFile& f, const InsertionEntry& e) {
  const InsertionViewEntry& v = *e.view;
  WallView w;
  w.model = e.model + ", " + stiffness_label(e.bending_stiffness) + ", " +
            decimals(e.steps[static_cast<std::size_t>(v.step)].insertion * 1e3, 3) + " mm";
  w.kind = e.model == "reference" ? "fem" : "model";
  w.level = -1;
  std::map<int, std::size_t> reference_node;  // mesh index → position in the reference's view
  const InsertionEntry* r = reference_at(f, e);
  if (r) {
    for (std::size_t k = 0; k < r->view->nodes.size(); ++k) reference_node[r->view->nodes[k]] = k;
  }
  for (std::size_t k = 0; k < v.nodes.size(); ++k) {
    const auto at = reference_node.find(v.nodes[k]);
    for (std::size_t c = 0; c < 3; ++c) {
      w.rest_mm.push_back(static_cast<float>(v.rest[3 * k + c] * 1e3));
      w.u_model_mm.push_back(static_cast<float>(v.displacement[3 * k + c] * 1e3));
      w.u_reference_mm.push_back(
          at == reference_node.end()
              ? 0.0F
              : static_cast<float>(r->view->displacement[3 * at->second + c] * 1e3));
    }
  }
  w.indices.assign(v.triangles.begin(), v.triangles.end());
  set_colour(w, pressure_kPa(v));
  return w;
}

/// The wire of e's view step, its nodes within 2 mm of the drawn wall's box (the camera frames
/// the wall, not the whole wire); none without a centreline.
std::optional<WireView> wire_near_wall(const InsertionEntry& e) {
  const InsertionStepEntry& step = e.steps[static_cast<std::size_t>(e.view->step)];
  if (step.centreline.empty()) return std::nullopt;
  Eigen::AlignedBox3d box;
  const std::vector<double>& rest = e.view->rest;
  for (std::size_t k = 0; k + 2 < rest.size(); k += 3) {
    box.extend(Vec3(rest[k], rest[k + 1], rest[k + 2]));
  }
  box.min().array() -= 2e-3;
  box.max().array() += 2e-3;
  WireView wire;
  wire.radius_mm = e.wire_radius * 1e3;
  for (std::size_t k = 0; k + 2 < step.centreline.size(); k += 3) {
    const Vec3 p(step.centreline[k], step.centreline[k + 1], step.centreline[k + 2]);
    if (box.contains(p)) wire.rigid_mm.push_back({p.x() * 1e3, p.y() * 1e3, p.z() * 1e3});
  }
  return wire;
}

}  // namespace

std::vector<SceneViews> insertion_views(const InsertionFile& f) {
  std::vector<SceneViews> out;
  std::set<std::string> done;
  for (const InsertionEntry& first : f.insertions) {
    if (!first.view || !done.insert(first.scene).second) continue;
    SceneViews s;
    s.scene = view_scene(first.scene);
    s.tolerance_mm.reset();
    s.colour_name = "contact pressure";
    s.colour_unit = "kPa";
    s.true_scale = true;
    s.load_text = "the step each names";
    const InsertionEntry* drawn = nullptr;  // whose wire is drawn: the reference's, else the first
    for (const InsertionEntry& e : f.insertions) {
      if (e.scene != first.scene || !e.view) continue;
      s.views.push_back(insertion_wall(f, e));
      if (!drawn || (e.model == "reference" && drawn->model != "reference")) drawn = &e;
    }
    s.qoi_mm = contact_centroid_mm(*drawn->view);
    s.view_from = dent_direction(*drawn->view);
    s.wire = wire_near_wall(*drawn);
    s.caption =
        "Each wall within 2 mm of where the wire bears at the insertion length in its name (its "
        "last converged step, or the one nearest vesselverify insertion --view-at), at true "
        "scale, coloured by the contact pressure (kPa: each node's force over its share of the "
        "wall's area at rest; viridis, one scale for every wall). Grey ghost: the reference's wall "
        "at the same step "
        "(at rest where the file has none). Red sphere: the force-weighted centroid of the "
        "contact on the wire's wall. Orange tube: the wire on " +
        drawn->model + "'s wall (" + stiffness_label(drawn->bending_stiffness) +
        "; its part near the drawn wall, in place and half transparent). The camera starts "
        "outside the lumen, looking onto the dent. Drag to turn, wheel to zoom; both panes share "
        "the camera; hover a node for its pressure and both displacements.";
    out.push_back(std::move(s));
  }
  return out;
}

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
    // A model's hub forces follow its contact force (its table gives them): the figure keeps the
    // reference's alone, readable beside every model's force.
    if (e.model != "reference") continue;
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
             "The contact force against the insertion length per wall and wire stiffness, and the "
             "reference's hub forces (converged steps).");
  std::set<std::string> viewed;
  for (const InsertionEntry& e : f.insertions) {
    if (e.view && viewed.insert(e.scene).second) doc.slot("view:" + view_scene(e.scene));
  }
}

std::string insertion_markdown(const InsertionFile& f) {
  Document doc;
  insertion_text(doc, f);
  return doc.markdown_text("figures");
}

}  // namespace vessel::reports
