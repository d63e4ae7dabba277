#pragma once
/// Comparison of a model's nodal displacements with the reference's at the same points: the
/// statistics seed 000 reports (max, mean, standard deviation, RMS of the nodal error) plus the
/// relative L2 error. Inputs in metres; the statistics are returned in millimetres.
#include <vector>

#include "meshes/tet_mesh.hpp"

namespace vessel {

struct ErrorStatistics {
  double max_mm = 0.0;     ///< max_i |u_i − u_ref,i|
  double mean_mm = 0.0;    ///< mean of |e_i|
  double stddev_mm = 0.0;  ///< population standard deviation of |e_i|
  double rms_mm = 0.0;     ///< sqrt(mean |e_i|²)
  double relative_l2 = 0.0;  ///< sqrt(Σ|e_i|²) / sqrt(Σ|u_ref,i|²) (0 if the reference is 0)
  std::size_t points = 0;
};

/// Statistics of e_i = model[i] − reference[i] (std::invalid_argument if the sizes differ or
/// are zero).
ErrorStatistics compare_displacements(const std::vector<Vec3>& model,
                                      const std::vector<Vec3>& reference);

}  // namespace vessel
