#pragma once
/// The critical time steps of the P1 tet models simulators run instead of springs (part of the
/// stability study): corotational P1 (msm/fem/corotational_tet.hpp) and XPBD FEM
/// (msm/fem/xpbd_fem.hpp) on the study's tube, ν = 0.45 (the contact scenes'), both ends clamped.
///   corotational P1, symplectic Euler and Verlet: the largest stable step found by bisection
///     (msm::find_stable_step, as for the springs), against 2/ω_max with ω_max of M⁻¹K at rest
///     (K: its Hessian there, linear P1's stiffness) by Lanczos and, independently, by power
///     iteration;
///   corotational P1, implicit Euler with the warped stiffness R K₀ Rᵀ re-assembled each step
///     ("implicit-euler") and with K₀ factorised once ("implicit-euler-rest"): unconditionally
///     stable at rest (K(rest) = K₀), so they run from rest under seed 000's largest contact load
///     (70 mN, where the wall turns) at steps up to a 30 Hz frame, bounded or not; where the
///     prefactored one diverges, its largest bounded step under that load is bisected (no closed
///     form predicts it: it is what the rest stiffness lacks of the turned wall's, integrated
///     explicitly);
///   XPBD FEM ("xpbd", its scene defaults: 4 sweeps, 2 % velocity damping per step): its
///     constraint solve is implicit, but the multipliers it carries from step to step act as an
///     explicit force along the step's initial gradients (msm/fem/xpbd_fem.hpp). Their stiffness
///     at rest, λ₀·∇²C summed over both constraints, is in F the 9×9 form μ(I − nnᵀ) − μ ∂²J
///     (n = I/√3): 2μ on symmetric traceless strains, 0 on rotations, −6μ on I's direction — the
///     whole shear stiffness of linear P1 and none of its bulk stiffness, i.e. linear P1 with
///     λ = −2μ/3 (bulk modulus 0) up to that volumetric term, which the implicit hydrostatic
///     constraint outweighs. So XPBD's critical step is that of symplectic Euler on the shear
///     stiffness: predicted 2/ω_max of M⁻¹K_dev, K_dev linear P1's stiffness with λ = −2μ/3
///     (Lanczos and power iteration), found by bisection from the same small random velocity.
///     Below it the steady state is the energy's equilibrium whatever the sweep count
///     (tests/msm/test_xpbd_fem.cpp); above it the run diverges.
#include <mutex>
#include <ostream>
#include <vector>

#include "meshes/tet_mesh.hpp"
#include "verification/harness/outcome.hpp"
#include "verification/scene.hpp"
#include "verification/studies/stability/stability.hpp"

namespace vessel::stability_study {

inline constexpr double kTetStepPoisson = 0.45;  ///< ν of the P1 rows (the contact scenes')
inline constexpr double kTetStepLoad = 0.07;     ///< N, the implicit rows' contact load
inline constexpr int kTetTrialSteps = 300;       ///< most steps per explicit and XPBD trial
inline constexpr int kTetImplicitSteps = 50;     ///< most steps per implicit trial

/// The P1 tet models' rows on `mesh` (the study scene `scene`'s, unloaded) at `level`:
/// min(steps, kTetTrialSteps) steps per explicit and XPBD trial, min(steps, kTetImplicitSteps) per
/// implicit one. Each row is logged
/// under `log_mutex`.
std::vector<TetStepRow> tet_step_rows(const Scene& scene, const TetMesh& mesh, int level, int steps,
                                      std::ostream& log, std::mutex& log_mutex);

/// The rows at levels 0..max_level (one level at a time per job, the finer first), each level's
/// computed or read from o.outcome_cache (`provenance`: one per level).
std::vector<TetStepRow> tet_critical_steps(const StabilityOptions& o, int max_level, int steps,
                                           std::ostream& log,
                                           std::vector<TimingProvenance>& provenance);

}  // namespace vessel::stability_study
