#pragma once
/// Stiffness rules: named functions from (E, ν, geometry) to spring constants. Each rule is
/// documented with its source; `assign_stiffness` applies one to a whole network.
/// Units: E in Pa, lengths in m, areas m², volumes m³, stiffness N/m.
#include <array>
#include <limits>
#include <string>
#include <vector>

#include "msm/topology/springs.hpp"

namespace vessel::msm {

enum class StiffnessRule {
  seed000,     ///< k = E·A/h0 (seed 000 eq. 4.2)
  seed001,     ///< k = E·V_T/L², V_T one third of the volume around the edge (seed 001 §2.2)
  van_gelder,  ///< k = E·Σ V_e/L² (3D) or E·t·Σ A_e/L² (2D), Van Gelder (1998)
  lloyd,       ///< Lloyd et al. (2007)'s closed form: (24/25)·E·Σ V_e/L², (√3/4)·E·t on triangles
  least_squares_fit,  ///< per-element least-squares fit of k to the element's FEM matrix at ν
  uniform,     ///< one k for every spring (comparison; seed 000 quotes k = 41.106)
};
/// Every rule, in declaration order (for sweeps over all of them, e.g. `vesselverify recommend`).
inline constexpr std::array<StiffnessRule, 6> kAllStiffnessRules{
    StiffnessRule::seed000,           StiffnessRule::seed001, StiffnessRule::van_gelder,
    StiffnessRule::lloyd,             StiffnessRule::least_squares_fit,
    StiffnessRule::uniform};
StiffnessRule parse_stiffness_rule(const std::string& name);
std::string to_string(StiffnessRule rule);

/// Material and per-family settings for assign_stiffness.
struct StiffnessParams {
  double youngs_modulus = 14.24e3;  ///< E, Pa (seed 000 §IV: 14.24 kPa)
  double poisson_ratio = 0.25;      ///< ν, used by the least_squares_fit rule only
  double uniform_k = 41.106;        ///< N/m, the uniform rule (seed 000 §IV: k = 41.106)
  /// Multipliers per family (surface springs: structural, shear, bend, two-ring; volume).
  double structural_factor = 1.0;
  double shear_factor = 1.0;
  double bend_factor = 1.0;
  double two_ring_factor = 1.0;
  double volume_factor = 1.0;
  /// Bilinear law (seed 001 eq. 1): k2 = bilinear_ratio·k1 beyond `bilinear_threshold` strain
  /// (elongation/rest length). Infinite threshold: Hooke springs.
  double bilinear_ratio = 1.0;
  double bilinear_threshold_strain = std::numeric_limits<double>::infinity();
};
/// Throws InputError naming the parameter: E ≤ 0 or not finite, ν outside [0, 0.5], negative
/// factor, uniform_k ≤ 0, bilinear ratio ≤ 0 or threshold ≤ 0.
void validate(const StiffnessParams& params);

/// seed 000 eq. (4.2): k = E·A/h0 (A the loaded cross-section, h0 the rest height).
double seed000_stiffness(double E, double area, double h0);
/// seed 001 §2.2: k = E·V_T/L² with V_T = (Σ volumes of the tets containing the edge)/3.
double seed001_stiffness(double E, double volume_around_edge, double L);
/// Van Gelder (1998), "Approximate simulation of elastic membranes by triangulated spring
/// meshes", J. Graphics Tools 3(2): k_c = E·t·Σ_e A_e/|c|² for triangles (the sum over the
/// triangles e sharing edge c), k_c = E·Σ_e V_e/|c|² for tetrahedra. Source check (2026-11): the
/// paper's full text could not be retrieved with the project's search corpora (docs, pages, code);
/// only its abstract was, which states the rule's "simplest form: stiffness varies as triangle
/// area over edge length squared" and that "extensions ... to three dimensions are discussed".
/// The proportionality constant E·t (so that an equilateral triangle reproduces the plane-stress
/// continuum at ν = 1/3) and the 3D form are therefore NOT checked against the paper's equations,
/// whose numbers cannot be cited here; any ν-dependence the paper may give is not implemented.
/// Tests check the properties that hold for this form (tests/msm/test_stiffness_papers.cpp).
double van_gelder_stiffness(double E, double measure_around_edge, double L);

/// Lloyd, Székely & Harders (2007), "Identification of spring parameters for deformable object
/// simulation", IEEE TVCG 13(5): the published closed forms (as the issue quotes them; the paper's
/// derivation matches the spring network's stiffness matrix to the linear FEM element's):
///   regular tetrahedron of edge l:   k = (2√2/25)·E·l   (valid at ν = 1/4, independent of ν);
///   equilateral triangle, thickness t: k = (√3/4)·E·t  (plane stress, valid at ν = 1/3).
/// Irregular elements, our choice among the two the issue names: per element k_e = (24/25)·E·V/L²
/// for a tet (t·A/L²·E for a triangle), summed over the elements sharing the edge, rather than the
/// regular-tet formula at the edge length of the regular tet of equal volume. Why: a spring's energy
/// under a uniform strain ε is ½·k·L²·(dᵀεd)², so k·L² ∝ V makes every element's energy density
/// independent of its size and shape distortion (an element's long edges are not overweighted),
/// as in Van Gelder's form, of which this is exactly 24/25; the equal-volume variant gives all six
/// edges of a tet one k, so a long edge of a stretched tet would carry (L/l_eq)² too much energy.
/// On the regular tet both agree: V = l³/(6√2), (24/25)·E·V/l² = (2√2/25)·E·l. On the triangle
/// E·t·A/L² = (√3/4)·E·t for the equilateral one, so on triangles this rule equals van_gelder.
/// Source check (2026-11): only the paper's abstract and introduction could be retrieved with the
/// project's search corpora ("analytical expressions for the spring parameters ... for triangle,
/// rectangle and tetrahedron meshes"); the two constants above are quoted from the project's
/// design notes, not checked against the paper's equations (no equation numbers cited). The tests
/// check the hand-derived values on one element (tests/msm/test_stiffness_rules_by_hand.cpp).
double lloyd_tet_edge_stiffness(double E, double volume, double L);
double lloyd_triangle_edge_stiffness(double E, double thickness, double area, double L);

/// Per-element least-squares fit of spring constants to the element's linear FEM stiffness matrix
/// K (isotropic, E and ν; triangles in plane stress with thickness t), in the spirit of
/// Natsupakpong & Çavuşoğlu (2010), "Determination of elasticity parameters in lumped element
/// (mass-spring) models of deformable objects", Graphical Models (2010),
/// doi:10.1016/j.gmod.2010.10.001: the network's matrix Σ_e k_e g_e g_eᵀ is matched to K in the
/// Frobenius norm, Σ_f (g_eᵀg_f)² k_f = g_eᵀ K g_e. Our own rule, not that paper's procedure (only
/// its summary was retrieved: per-element optimisation minimising the error between the lumped
/// and FEM element stiffness matrices; its error measure and constraints are not reproduced). Hand-derived (tests): regular tet of edge l,
/// k = (√2/15)·(λ + 2μ)·l, which at ν = 1/4 is Lloyd's (2√2/25)·E·l and grows without bound as
/// ν → 1/2 (3.16× at 0.45); equilateral triangle k = (2√3/9)·E·t/(1 − ν²), exact at ν = 1/3.
/// Returns the k of the 6 edges (0-1, 0-2, 0-3, 1-2, 1-3, 2-3) of a tetrahedron, N/m.
std::array<double, 6> least_squares_fit_tet_stiffness(const std::array<Vec3, 4>& x, double E,
                                                      double nu);
/// The k of the 3 edges (0-1, 0-2, 1-2) of a triangle of thickness t, N/m.
std::array<double, 3> least_squares_fit_triangle_stiffness(const std::array<Vec3, 3>& x, double E,
                                                           double nu, double t);
/// Linear FEM stiffness matrix of a P1 tetrahedron (12×12) and of a plane-stress triangle of
/// thickness t (9×9, in-plane), N/m. Used by the least_squares_fit rule and by tests.
Eigen::MatrixXd fem_tet_stiffness(const std::array<Vec3, 4>& x, double E, double nu);
Eigen::MatrixXd fem_triangle_stiffness(const std::array<Vec3, 3>& x, double E, double nu, double t);

/// Sets law.k1 (and the bilinear k2, threshold) of every spring of the network by the rule and
/// the family factors. Volume networks use their tets; surface networks their triangles with the
/// network's thickness t. Springs other than structural and volume ones (bend, shear, two-ring)
/// are not taken as element edges, even where one coincides with a cut diagonal: the seed000 rule
/// gives them k = E·t·h0/h0 = E·t (A = t·h0, the square patch a surface spring spans; k = E·h0 for
/// volume springs, A = h0²); seed001, van_gelder, lloyd and least_squares_fit use the measure of
/// one equilateral triangle on the spring, t·(√3/4)·L² (seed001 takes a third of it), i.e.
/// k = (√3/4)·E·t for van_gelder, lloyd and least_squares_fit.
void assign_stiffness(SpringNetwork& network, StiffnessRule rule, const StiffnessParams& params);

}  // namespace vessel::msm
