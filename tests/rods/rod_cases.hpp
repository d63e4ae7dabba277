#pragma once
/// The closed-form cases run on every rod model through one small adapter per model: a uniform
/// cantilever along x clamped at the origin (L = 1 m, d = 1 mm: EA L²/EI = 1.6e7, so axial strain
/// stays below 1e-6 of the bending answers), loaded in the x–y plane.
#include <Eigen/Core>
#include <memory>
#include <string>

#include "msm/rods/corde_rod.hpp"
#include "msm/rods/rod_layout.hpp"

namespace vessel::msm::rods::test {

inline RodMaterial test_material() { return {50e9, 50e9 / (2.0 * 1.33), 6450.0}; }
constexpr double kLength = 1.0;
constexpr double kDiameter = 1e-3;
inline double test_EI() { return solid_section(test_material(), kDiameter).EI; }
inline double test_rhoA() { return solid_section(test_material(), kDiameter).rhoA; }

class RodAdapter {
 public:
  virtual ~RodAdapter() = default;
  [[nodiscard]] virtual std::string name() const = 0;
  /// Tip (x, y) of an N-segment cantilever under dead tip force (fx, fy) (N) and end moment
  /// about z (N·m), loaded in `steps` increments.
  virtual Eigen::Vector2d tip(int segments, double fx, double fy, double moment, int steps) = 0;
  /// Smallest compressive tip load (N) at which the straight cantilever loses stability.
  virtual double buckling_load(int segments) = 0;
  /// Lowest bending natural frequency of the cantilever, rad/s.
  virtual double first_frequency(int segments) = 0;
  /// Shear flexibility added to the tip deflection under a tip force F, per newton (m/N): zero
  /// for an unshearable model.
  [[nodiscard]] virtual double shear_compliance() const { return 0.0; }
};

std::unique_ptr<RodAdapter> make_der_adapter();
/// CORDE with alignment penalty κ (N; ≤ 0: the section's shear stiffness 0.9 G A) and Darboux
/// measure (the paper's quaternion form, or the rotation vector: name "CORDE-rotvec").
std::unique_ptr<RodAdapter> make_corde_adapter(double alignment = 0.0,
                                               DarbouxMeasure measure = DarbouxMeasure::quaternion);

}  // namespace vessel::msm::rods::test
