#pragma once
/// A user's own guidewire model (a guidewire load's `model = "external"`): the wire's problem as
/// an exchange case and the user's program run on it, as the user's own vessel models are
/// (verification/harness/external_model.hpp). The case folder holds manifest.json (schema
/// `vesselverify.exchange`, verification/exchange.schema.json, with a "wire" object: the rest
/// centreline, section, material, clamp, and the lumen the centreline must stay inside); the
/// program answers beside it with centreline.csv (header `node,x,y,z`, one line per node of the
/// rest centreline, m, node 0 at the clamp) and contact.json (`{"force_N": F, "node": k}`: the
/// wall's normal force on the wire, N, ≥ 0, and the node it acts on; 0 and any node when the wire
/// does not touch).
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "meshes/tet_mesh.hpp"
#include "verification/guidewire/guidewire_spec.hpp"

namespace vessel {

/// The user's wire program failed on a case (non-zero exit, time-out, missing or malformed
/// answer): the message names the file and what is wrong, with the log's last lines.
class WireModelError : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The rigid lumen a wire case gives: a straight tube (axis through the origin along z) or the
/// arch's torus (centre at the origin, in the xy-plane); the centreline must keep its distance
/// from the lumen's centreline ≤ `offset` (the lumen's radius less the wire's, plus any give).
struct WireLumen {
  bool torus = false;
  double bend_radius = 0.0;  ///< m (torus)
  double offset = 0.0;       ///< m
};

/// Writes `dir`/manifest.json for the wire of `spec` inserted `length` into `lumen` (and removes
/// any answer an earlier run left there).
void write_wire_case(const std::filesystem::path& dir, const std::string& scene,
                     const GuidewireSpec& spec, double length, const WireLumen& lumen);

struct WireAnswer {
  std::vector<Vec3> centreline;  ///< m, clamp to tip
  double force = 0.0;            ///< N
  int node = 0;                  ///< the contact node
};

/// Reads centreline.csv and contact.json in `dir`, expecting `nodes` nodes. WireModelError naming
/// the file: missing, a malformed line, a node missing, repeated or out of range, a value that is
/// not finite, a negative force, a contact node out of range.
WireAnswer read_wire_answer(const std::filesystem::path& dir, int nodes);

/// Runs `spec.command` plus the manifest's absolute path in spec.working_dir (with
/// VESSELVERIFY_MANIFEST and VESSELVERIFY_CASE_DIR set, output in dir/simulator.log, killed after
/// spec.timeout_s) on the case in `dir`, then reads its answer. WireModelError when it fails.
WireAnswer run_wire_case(const GuidewireSpec& spec, const std::filesystem::path& dir, int nodes);

}  // namespace vessel
