#pragma once
/// Grid-convergence arithmetic: observed order from errors on refined meshes, Richardson
/// extrapolation and Roache's grid convergence index (GCI), so every report can print the
/// reference's own discretisation uncertainty next to a model error.
#include <optional>
#include <string>
#include <vector>

#include "meshes/tet_mesh.hpp"

namespace vessel::fem {

/// Observed order p = ln(e_coarse / e_fine) / ln(ratio) of an error that falls from e_coarse to
/// e_fine when h shrinks by `ratio` (> 1). std::invalid_argument for non-positive inputs.
double observed_order(double e_coarse, double e_fine, double ratio = 2.0);

/// Observed order from three solutions on meshes refined by a constant ratio (Roache 1998,
/// eq. 5.10.6.1): p = ln((f3 − f2)/(f2 − f1)) / ln(r), f1 the finest. std::domain_error when the
/// differences have opposite signs (oscillatory convergence) or are zero.
double observed_order_three(double f_coarse, double f_medium, double f_fine, double ratio = 2.0);

struct RichardsonEstimate {
  double extrapolated = 0.0;  ///< f_exact ≈ f1 + (f1 − f2)/(r^p − 1)
  double error_fine = 0.0;    ///< |f_exact − f1|, the estimated error of the finest solution
  double gci_fine = 0.0;      ///< GCI_fine = Fs |f1 − f2| / (|f1| (r^p − 1)), relative
};

/// Richardson extrapolation (Richardson 1911; Roache, Verification and Validation in
/// Computational Science and Engineering, 1998, §5.6) from the two finest solutions f_medium,
/// f_fine with order p, and the grid convergence index with safety factor Fs (1.25 with an
/// observed order from three grids, 3 with an assumed one).
RichardsonEstimate richardson(double f_medium, double f_fine, double order, double ratio = 2.0,
                              double safety_factor = 1.25);

/// The order a Richardson/GCI estimate uses, and where it came from.
struct GciOrder {
  double order = 0.0;
  std::string source;          ///< "observed" (three levels) or "assumed"
  double safety_factor = 3.0;  ///< Roache: 1.25 with an order observed on three grids, else 3
  std::string note;            ///< how it was chosen (observed value, clamping, or why assumed)
};

/// Roache's procedure (Verification and Validation in Computational Science and Engineering,
/// 1998, §5.10): with a quantity on three levels (`three`: coarse, medium, fine; refinement
/// ratio `ratio`) the observed order p = observed_order_three, clamped to [min_order, max_order]
/// (a wildly small or large p from non-asymptotic levels would make the GCI meaningless), with
/// safety factor 1.25. Without three levels, or when they converge oscillatorily (differences of
/// opposite sign, or zero), the stated `assumed` order with safety factor 3.
/// std::invalid_argument unless 0 < min_order ≤ assumed ≤ max_order.
GciOrder gci_order(const std::optional<std::vector<double>>& three, double assumed,
                   double ratio = 2.0, double min_order = 0.5, double max_order = 3.0);

/// The reference's discretisation uncertainty at a set of points (e.g. mass-spring nodes), from
/// its displacement there on the two finest levels.
struct FieldUncertainty {
  std::vector<double> error_fine;  ///< |u_ext − u_fine| per point, m (Richardson estimate)
  double max_error = 0.0;          ///< m
  double rms_error = 0.0;          ///< m
  double relative_l2 = 0.0;        ///< ‖u_ext − u_fine‖ / ‖u_fine‖ over the points
};

/// Pointwise Richardson extrapolation u_ext = u_fine + (u_fine − u_medium)/(r^p − 1) of a
/// displacement field sampled at the same points on two levels (refinement ratio r, order p, e.g.
/// the observed order of the Lamé verification). std::invalid_argument for unequal sizes.
FieldUncertainty richardson_field(const std::vector<Vec3>& medium, const std::vector<Vec3>& fine,
                                  double order, double ratio = 2.0);

}  // namespace vessel::fem
