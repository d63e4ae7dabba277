#pragma once
/// A guidewire scene with coupling = "contact": each of the scene's models with a wall, and the FEM
/// P2 wall as the reference, in the same wire–wall contact solve
/// (verification/contact_models/contact_models.hpp: the contact between the wire's surface and
/// the inner wall found by the solve, on one mesh refined around the wire's contact, the wire and
/// each wall as one potential; with contact_wall = "linear" every wall linearised at rest and
/// condensed on a growing band, with "neo-hookean" the reference the neo-Hookean FEM wall and
/// each model at its own nonlinear equilibrium) at each EI of the scene (its wire's, then its
/// stiffness_sweep); each model's contact force, zone, dent and tip judged against the reference's,
/// and the shortcuts a simulator takes instead of a contact solve (the rigid lumen's force, the
/// series springs of guidewire_coupling.hpp) judged against the same reference.
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "verification/contact_models/contact_models.hpp"
#include "verification/guidewire/guidewire_outcome.hpp"
#include "verification/harness/options.hpp"
#include "verification/harness/outcome.hpp"

namespace vessel {

/// A force a simulator would use instead of the contact solve's, at one EI.
struct GuidewireShortcut {
  std::string name;    ///< "rigid lumen", "series springs, <model> (level L)", ...
  double force = 0.0;  ///< N
};

struct GuidewireContact {
  contact::ContactModels solve;
  contact::ContactModelsOptions options;  ///< what it was solved with (its log unset)
  ContactWall wall = ContactWall::linear;  ///< the scene's contact_wall
  /// The linear reference's validity: its largest small strain at most this (the contact
  /// reference's limit, contact_reference.hpp); a run beyond it is the regime, not a prediction.
  double strain_limit = 0.1;
  std::vector<std::vector<GuidewireShortcut>> shortcuts;  ///< per run (EI)
  TimingProvenance provenance;
  [[nodiscard]] bool within_linear_validity(const contact::ContactModelsRun& run) const {
    return run.reference.failure.empty() && run.reference.strain <= strain_limit;
  }
  /// A run whose rows show the regime rather than a prediction: a linear reference strained
  /// beyond its validity (the neo-Hookean reference has no such limit).
  [[nodiscard]] bool beyond_its_reference(const contact::ContactModelsRun& run) const {
    return wall == ContactWall::linear && !within_linear_validity(run);
  }
};

/// Budget quantity contact_force: `model`'s contact-force error over the runs (EIs),
/// |F_model − F_reference| at the worst EI, mN; nullopt with `why` set where the model has no wall
/// in the solve, its solve or the reference's failed at an EI, or the linear reference is
/// strained beyond its validity there (the finite-strain reference judges that regime).
std::optional<double> worst_contact_force_error_mN(const GuidewireContact& contact,
                                                   const std::string& model, std::string& why);

/// The options of `scene`'s contact solve: the EIs its walls can hold (the wire's own alone in the
/// quick variant), the contact mesh's size and refined radius, the wire and each wall as one
/// potential (linear walls condensed on the band; at finite strain each at its own equilibrium,
/// the P2 reference from P1's where the scene asks, contact_p1_start).
contact::ContactModelsOptions guidewire_contact_options(const Scene& scene,
                                                        const GuidewireOutcome& coupled,
                                                        const HarnessOptions& options);

/// The contact of `scene` (coupling = "contact") at guidewire_stiffnesses, its solve read from
/// options.outcome_cache when a run of the same executable on this machine kept it (keyed by the
/// scene file's text and the solve's options); the shortcuts from `coupled` (its rigid forces and
/// series-spring rows at the contact's ν). Progress lines on options.log.
GuidewireContact solve_guidewire_contact(const Scene& scene, const GuidewireOutcome& coupled,
                                         const HarnessOptions& options);

/// results.json's "guidewire"."contact" object (schema verification/results.schema.json).
nlohmann::json guidewire_contact_json(const GuidewireContact& c);

/// summary.md's table per EI: the reference, each model's force error, zone, dent and tip error,
/// and the shortcuts' force errors.
void write_guidewire_contact_markdown(std::ostream& out, const GuidewireContact& c);

}  // namespace vessel
