#include "msm/model/mass_spring_model.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "msm/terms/four_node_blocks.hpp"

namespace vessel::msm {

MassSpringModel::MassSpringModel(const SpringNetwork& network, double point_damping,
                                 const ModelTerms& terms)
    : springs_(network, point_damping), terms_(make_terms(network, terms)) {
  if (terms_.empty()) return;
  SparseMatrix Hs;
  springs_.hessian(flatten(network.nodes), Hs, false);
  bool missing = false;
  for (const auto& t : terms_) {
    term_slots_.push_back(t->slots_in(Hs));
    missing = missing || std::find(term_slots_.back().begin(), term_slots_.back().end(), -1) !=
                             term_slots_.back().end();
  }
  if (!missing) return;
  // Some term entries are not in the springs' pattern (a region of interest drops the springs
  // between two held nodes; a hinge couples its two opposite vertices, which no spring joins once
  // the bend springs are dropped; the edge-pair model has no springs): assemble into the union of
  // the patterns.
  union_pattern_ = Hs;
  for (const auto& t : terms_) union_pattern_ += t->pattern();
  union_pattern_.makeCompressed();
  std::fill(union_pattern_.valuePtr(), union_pattern_.valuePtr() + union_pattern_.nonZeros(), 0.0);
  for (int col = 0; col < Hs.outerSize(); ++col) {
    for (SparseMatrix::InnerIterator it(Hs, col); it; ++it) {
      spring_to_union_.push_back(pattern_slot(union_pattern_, static_cast<int>(it.row()), col));
    }
  }
  for (std::size_t k = 0; k < terms_.size(); ++k) {
    term_slots_[k] = terms_[k]->slots_in(union_pattern_);
  }
}

double MassSpringModel::max_strain(const VectorXd& x) const {
  double strain = springs_.max_strain(x);
  for (const auto& t : terms_) strain = std::max(strain, t->max_strain(x));
  return strain;
}

double MassSpringModel::energy(const VectorXd& x) const {
  double e = springs_.energy(x);
  for (const auto& t : terms_) e += t->energy(x);
  return e;
}

void MassSpringModel::gradient(const VectorXd& x, VectorXd& g) const {
  springs_.gradient(x, g);
  for (const auto& t : terms_) t->add_gradient(x, g);
}

double MassSpringModel::energy_gradient(const VectorXd& x, VectorXd& g) const {
  double e = springs_.energy_gradient(x, g);
  for (const auto& t : terms_) {
    t->add_gradient(x, g);
    e += t->energy(x);
  }
  return e;
}

void MassSpringModel::hessian(const VectorXd& x, SparseMatrix& H, bool project_psd) const {
  if (spring_to_union_.empty()) {
    springs_.hessian(x, H, project_psd);
  } else {
    SparseMatrix Hs;
    springs_.hessian(x, Hs, project_psd);
    H = union_pattern_;
    double* values = H.valuePtr();
    const double* spring_values = Hs.valuePtr();
    for (std::size_t k = 0; k < spring_to_union_.size(); ++k) {
      values[spring_to_union_[k]] += spring_values[k];
    }
  }
  // Each term's blocks are projected separately (per spring, per tet, per hinge).
  for (std::size_t k = 0; k < terms_.size(); ++k) {
    terms_[k]->add_hessian(x, H.valuePtr(), term_slots_[k], project_psd);
  }
}

void MassSpringModel::damping_force(const VectorXd& x, const VectorXd& v, VectorXd& f) const {
  springs_.damping_force(x, v, f);
}

void MassSpringModel::damping_jacobian(const VectorXd& x, SparseMatrix& D) const {
  springs_.damping_jacobian(x, D);
}

std::unique_ptr<MassSpringModel> make_model(const SpringNetwork& network,
                                            const ModelTerms& terms, double point_damping) {
  return std::make_unique<MassSpringModel>(network, point_damping, terms);
}

std::unique_ptr<MassSpringModel> make_model(const BuiltNetwork& built, double point_damping) {
  return make_model(built.network, built.terms, point_damping);
}

const SpringModel* plain_spring_model(const Form& form) {
  if (const auto* springs = dynamic_cast<const SpringModel*>(&form)) return springs;
  if (const auto* model = dynamic_cast<const MassSpringModel*>(&form)) {
    if (model->springs_only()) return &model->springs();
  }
  return nullptr;
}

}  // namespace vessel::msm
