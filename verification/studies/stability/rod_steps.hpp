#pragma once
/// The guidewire's critical time step (part of the stability study): a metal wire clamped at one
/// end, free at the other, as msm/rods models it. Explicit integrators (symplectic Euler, Verlet)
/// on the Discrete Elastic Rod: the largest stable step found by bisection on the integrator
/// (msm::find_stable_step), against the closed forms of the straight discrete rod's three wave
/// families at rest (they decouple there):
///   axial    a chain of springs EA/h and masses ρA·h:  ω_max = (2/h)·√(E/ρ),  dt = h/c,
///            c = √(E/ρ) (the Courant limit of the 1D wave equation);
///   twist    springs GJ/h and inertias ρJ·h:          ω_max = (2/h)·√(G/ρ),  dt = h/√(G/ρ);
///   bending  the turning angle (w_{i+1} − 2w_i + w_{i−1})/h, energy Σ EI/(2h)·angle², so
///            K = (EI/h³)·Δ⁴ with masses ρA·h; the mode w_i = (−1)^i maximises Δ⁴'s symbol
///            (2 − 2cos kh)² = 16 at kh = π: ω_max = (4/h²)·√(EI/(ρA)), dt = h²/(2√(EI/(ρA)))
///            (the Euler–Bernoulli dispersion ω = k²√(EI/ρA) with k → 2 sin(kh/2)/h).
/// dt = 2/ω_max for symplectic Euler and Verlet; the smallest of the three binds (axial for a
/// slender wire: bending's dt is axial's times 2h/d). The implicit integrators (DER and CORDE by
/// rod_implicit_euler_step, each step converged; the XPBD rod) are run at steps up to
/// 1/30 s instead: stable at every step tried is what they claim.
#include <ostream>
#include <vector>

#include "msm/rods/rod.hpp"
#include "msm/rods/rod_layout.hpp"
#include "msm/solvers/integrators.hpp"
#include "verification/guidewire/guidewire_spec.hpp"
#include "verification/studies/stability/stability.hpp"

namespace vessel::stability_study {

/// The three closed-form critical steps of a straight discrete rod of segment h (s).
struct RodStepClosedForm {
  double h = 0.0;  ///< m
  double axial_dt = 0.0, twist_dt = 0.0, bending_dt = 0.0;
  double dt = 0.0;  ///< the smallest
};
RodStepClosedForm rod_step_closed_form(const msm::rods::SectionStiffness& section, double h);

/// DER on `layout` (its sections may differ from the wire's): ω_max by Lanczos, the found step
/// by bisection (`steps` per trial) with `integrator` (symplectic Euler or Verlet).
RodStepRow der_explicit_row(const msm::rods::RodLayout& layout, msm::Integrator integrator,
                            int steps);

/// The implicit rows at each step of `dts` (s), `steps` steps per trial from a small random
/// velocity (XPBD: from a tip load held 5 steps, then released): bounded or not. implicit_row
/// steps any rod model by rod_implicit_euler_step (`model` names the row).
RodStepRow implicit_row(msm::rods::Rod& rod, WireModel model, const std::vector<double>& dts,
                        int steps);
RodStepRow xpbd_row(const msm::rods::RodLayout& layout, const std::vector<double>& dts, int steps);

/// Every row for the wire at each segment count: DER symplectic Euler and Verlet (found step),
/// DER implicit Euler, CORDE implicit Euler and XPBD (at steps up to 1/30 s).
std::vector<RodStepRow> rod_critical_steps(const RodWire& wire, int steps, std::ostream& log);

}  // namespace vessel::stability_study
