#pragma once
/// What `vesselverify msm --json` writes (schema "vesselverify.msm_result", version 1): the model,
/// its springs, the load it carried (with the contact's point, normal and patch area) and what the
/// solver did. Units in the file: mm, mN, s.
#include <filesystem>
#include <map>
#include <optional>
#include <string>

#include "msm/solvers/solve.hpp"
#include "verification/fem_document.hpp"

namespace vessel {

struct MsmRunRecord {
  VesselParams vessel;
  std::string model, surface, topology, stiffness_rule, mass_rule;
  std::string input;  ///< the mesh file, empty for a generated vessel
  std::size_t nodes = 0;
  std::map<std::string, std::size_t> springs;  ///< per family
  double build_seconds = 0.0, total_seconds = 0.0;
  std::optional<ContactRecord> contact;  ///< displacement: at the network node nearest the point
  std::string solver;
  msm::SolveResult solve;
  double max_displacement = 0.0;   ///< m
  double max_spring_strain = 0.0;  ///< |L − l|/l
};

std::string msm_json(const MsmRunRecord& run);
void write_msm_json(const std::filesystem::path& path, const MsmRunRecord& run);

}  // namespace vessel
