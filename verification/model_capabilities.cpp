#include "verification/model_capabilities.hpp"

#include "meshes/foundation/errors.hpp"
#include "msm/terms/edge_pair_term.hpp"
#include "msm/model/mass_spring_model.hpp"
#include "msm/stiffness/hybrid_moduli.hpp"
#include "msm/formats/network_file.hpp"
#include "msm/terms/volume_term_homogenised.hpp"
#include "verification/calibration_file.hpp"

namespace vessel {

std::string model_refusal(const ModelSpec& spec, double youngs_modulus, double nu) {
  if (spec.volume_term) {
    return spec.volume_moduli == msm::VolumeModuli::golec
               ? msm::hybrid_refusal(youngs_modulus, nu)
               : msm::homogenised_refusal(youngs_modulus, nu);
  }
  if (spec.edge_pairs) return msm::edge_pair_refusal(youngs_modulus, nu);
  if (spec.kind == ModelKind::corotational_fem || spec.kind == ModelKind::xpbd_fem) {
    if (!(nu >= 0.0 && nu < 0.5)) {
      return to_string(spec.kind) + ": expected Poisson's ratio ν in [0, 0.5), got " +
             std::to_string(nu) + " (P1 tets in displacement form: λ is infinite at ν = 0.5)";
    }
  }
  return {};
}

std::vector<RequiredFile> required_files(const ModelSpec& spec) {
  std::vector<RequiredFile> files;
  if (!spec.calibration.empty()) files.push_back({"calibration", spec.calibration});
  if (spec.kind == ModelKind::network) files.push_back({"file", spec.network_file});
  return files;
}

void check_model_inputs(const Scene& scene) {
  for (const ModelSpec& spec : scene.models) {
    for (const RequiredFile& f : required_files(spec)) {
      try {
        if (f.key == "calibration") {
          (void)read_calibration(f.path);
        } else {
          (void)msm::read_network_file(f.path);
        }
      } catch (const InputError& e) {
        throw InputError(scene.source.string() + ": model '" + spec.name + "', key '" + f.key +
                         "': " + e.what());
      }
    }
  }
}

}  // namespace vessel
