#include "msm/rods/corde_rod.hpp"
#include "msm/rods/rod_loads.hpp"
#include "msm/rods/rod_statics.hpp"
#include "rod_cases.hpp"
#include "rod_eigen.hpp"

namespace vessel::msm::rods::test {
namespace {

class CordeAdapter : public RodAdapter {
 public:
  CordeAdapter(double alignment, DarbouxMeasure measure) : alignment_(alignment), measure_(measure) {}
  [[nodiscard]] std::string name() const override {
    return measure_ == DarbouxMeasure::quaternion ? "CORDE" : "CORDE-rotvec";
  }

  CordeRod make(int segments) const {
    return CordeRod(make_layout(uniform_rod(test_material(), kLength, kDiameter, segments)),
                    alignment_, true, measure_);
  }

  Eigen::Vector2d tip(int segments, double fx, double fy, double moment, int steps) override {
    CordeRod rod = make(segments);
    PlanarEndMoment end_moment(rod.layout(), rod.num_dofs(), Eigen::Vector3d::UnitZ());
    RodStaticLoad load;
    load.force = VectorXd::Zero(rod.num_dofs());
    const int tip = rod.layout().tip_node;
    load.force[3 * tip] = fx;
    load.force[3 * tip + 1] = fy;
    if (moment != 0.0) {
      load.extra = &end_moment;
      load.scale_extra = [&](double s) { end_moment.set_moment(s * moment); };
    }
    load.steps = steps;
    last_ = solve_rod_static(rod, load);
    return last_.x.segment<2>(3 * tip);
  }

  double buckling_load(int segments) override {
    const CordeRod rod = make(segments);
    const VectorXd x = rod.rest_state();
    SparseMatrix J, H;
    rod.jacobian(x, J);
    rod.hessian(x, H, false);
    const double l = kLength / segments;
    // Straight equilibrium under a compressive tip load P: every stretch multiplier is −P/(2l).
    const auto min_eigenvalue = [&](double P) {
      VectorXd lambda = VectorXd::Zero(rod.num_constraints());
      for (int r = 0; r < lambda.size(); r += 2) lambda[r] = -P / (2.0 * l);
      SparseMatrix Hc;
      rod.weighted_hessian(x, lambda, Hc);
      return smallest_constrained_eigenvalue(H + Hc, J, rod.clamp_fixed());
    };
    return find_sign_change(min_eigenvalue, 0.5 * test_EI(), 0.5 * test_EI() * 10.0);
  }

  double first_frequency(int segments) override {
    const CordeRod rod = make(segments);
    SparseMatrix K, J;
    rod.hessian(rod.rest_state(), K, false);
    rod.jacobian(rod.rest_state(), J);
    return std::sqrt(smallest_constrained_generalised(K, rod.lumped_mass(), J, rod.clamp_fixed()));
  }

  [[nodiscard]] double shear_compliance() const override {
    return kLength / make(1).alignment();
  }

  RodStaticResult last_;

 private:
  double alignment_;
  DarbouxMeasure measure_;
};

}  // namespace

std::unique_ptr<RodAdapter> make_corde_adapter(double alignment, DarbouxMeasure measure) {
  return std::make_unique<CordeAdapter>(alignment, measure);
}

}  // namespace vessel::msm::rods::test
