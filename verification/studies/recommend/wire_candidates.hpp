#pragma once
/// The guidewire's candidates of `vesselverify recommend`, for scenes whose load is a guidewire:
/// the rod models msm/rods solves against the rigid lumen (Discrete Elastic Rods, seed 002's
/// CORDE rod, the XPBD rod's steady state) at a few segment counts, each judged against the
/// continuum wire (fem_reference/rod_theory: Kirchhoff shooting in the straight tube, the
/// quarter-wave elastica at the arch's apex) and on its time per update, set-up (the first
/// insertion) apart, the median of 10 updates. A static model's update is what a quasi-static
/// simulator pays: the wire moved by the distance it travels in one update at 10 mm/s, solved
/// again from its last equilibrium. XPBD's is what a dynamic simulator pays: one step of the
/// update period (2 direct iterations); its error is its steady state's, which a simulator sees
/// once the wire has come to rest. The error is the one the budget's
/// unit asks for: the contact force's (mN) for a reaction budget, else the contact point's (mm).
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <vector>

#include "verification/guidewire/guidewire_load.hpp"
#include "verification/scene.hpp"
#include "verification/studies/recommend/recommend.hpp"

namespace vessel {

/// The continuum wire of the scene's guidewire load (continuum_wire of guidewire_load.hpp);
/// nullopt (and `why`) without a guidewire load or a continuum wire for its pose.
std::optional<WireReference> continuum_wire(const Scene& scene, std::string& why);

struct WireCandidate {
  std::string name;   ///< "wire/der @ N32"
  std::string model;  ///< der | corde | xpbd
  int segments = 0;
  bool ok = false;
  std::string failure;
  double force = 0.0;             ///< N
  double force_error_mN = 0.0;    ///< |F − F_continuum|
  double contact_error_mm = 0.0;  ///< |p − p_continuum|
  double error = 0.0;             ///< the one the budget's unit asks for
  double update_seconds = 0.0;    ///< median of the timed updates
  std::string update;             ///< what one timed update is
  double setup_seconds = 0.0;     ///< the first insertion
};

struct WireRecommendation {
  std::optional<WireReference> reference;
  std::string no_reference;  ///< why there is none (then no candidate is run)
  std::vector<WireCandidate> candidates;
  Selection selection;  ///< select_model on the candidates
};

/// The wire's candidates of `scene` (a guidewire load and a stated budget): models × segments.
WireRecommendation recommend_wire(const Scene& scene,
                                  const std::vector<WireModel>& models = {kRodModels.begin(),
                                                                          kRodModels.end()},
                                  const std::vector<int>& segments = {8, 16, 32, 64});

/// The same candidates judged against another budget (time per update, tolerance, unit).
Selection judge_wire(const std::vector<WireCandidate>& candidates, const Budget& budget);

/// recommend.json's "wire" object.
nlohmann::json wire_recommendation_json(const WireRecommendation& w);

}  // namespace vessel
