#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

#include "msm/rods/der_rod.hpp"
#include "msm/rods/rod_loads.hpp"
#include "msm/rods/rod_statics.hpp"
#include "rod_cases.hpp"
#include "rod_eigen.hpp"

namespace vessel::msm::rods::test {
namespace {

class DerAdapter : public RodAdapter {
 public:
  [[nodiscard]] std::string name() const override { return "DER"; }

  Eigen::Vector2d tip(int segments, double fx, double fy, double moment, int steps) override {
    DerRod rod(make_layout(uniform_rod(test_material(), kLength, kDiameter, segments)));
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
    const VectorXd x = solve_rod_static(rod, load, 1e-11).x;
    return x.segment<2>(3 * tip);
  }

  double buckling_load(int segments) override {
    DerRod rod(make_layout(uniform_rod(test_material(), kLength, kDiameter, segments)));
    const double EA = rod.layout().section[1].EA;
    const auto fixed = rod.clamp_fixed();
    // The compressed straight state is an equilibrium for every P; its Hessian loses
    // definiteness at the critical load.
    const auto min_eigenvalue = [&](double P) {
      VectorXd x = rod.rest_state();
      for (int i = 0; i < rod.num_nodes(); ++i) x[3 * i] *= 1.0 - P / EA;
      SparseMatrix H;
      rod.hessian(x, H, false);
      return smallest_eigenvalue(H, fixed);
    };
    return find_sign_change(min_eigenvalue, 0.5 * test_EI(), 0.5 * test_EI() * 10.0);
  }

  double first_frequency(int segments) override {
    DerRod rod(make_layout(uniform_rod(test_material(), kLength, kDiameter, segments)));
    SparseMatrix K;
    rod.hessian(rod.rest_state(), K, false);
    return std::sqrt(smallest_generalised_eigenvalue(K, rod.lumped_mass(), rod.clamp_fixed()));
  }
};

}  // namespace

std::unique_ptr<RodAdapter> make_der_adapter() { return std::make_unique<DerAdapter>(); }

}  // namespace vessel::msm::rods::test
