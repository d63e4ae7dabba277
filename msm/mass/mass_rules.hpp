#pragma once
/// Nodal masses of a spring network (kg per node).
#include <string>
#include <vector>

#include "msm/topology/springs.hpp"

namespace vessel::msm {

enum class MassRule {
  uniform,     ///< total mass spread evenly over the nodes (seed 000 §III.A)
  seed001,     ///< tet-volume lumping, seed 001 eq. (2), rescaled to the total mass
  consistent,  ///< density-consistent lumping: ρV/4 per tet vertex, ρ·A·t/3 per triangle vertex
};
MassRule parse_mass_rule(const std::string& name);
std::string to_string(MassRule rule);

/// Default density of vessel wall, kg/m³.
inline constexpr double kVesselDensity = 1060.0;

/// Total mass of the network's material, kg: ρ·Σ V (volume) or ρ·t·Σ A (surface).
double network_mass(const SpringNetwork& net, double density);

/// seed 001 eq. (2) exactly as printed: M_i = M·V_i/(V·N_i·3), V_i the volume of the N_i tets
/// around node i, V the total volume. As printed it does not conserve mass (Σ M_i ≠ M in
/// general, since Σ V_i = 4V); `seed001_masses` returns these raw values.
std::vector<double> seed001_masses_as_printed(const SpringNetwork& net, double total_mass);

/// Nodal masses by the rule, kg, summing to the network's mass ρ·(volume or t·area). The seed001
/// rule rescales eq. (2)'s distribution (∝ V_i/N_i, the mean volume of the tets around node i) to
/// that total. Throws InputError if density ≤ 0, or seed001 on a network without tets.
std::vector<double> nodal_masses(const SpringNetwork& net, MassRule rule, double density);

}  // namespace vessel::msm
