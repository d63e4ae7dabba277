#pragma once
/// What `vesselverify fem` writes: its JSON summary (schema "vesselverify.fem", version 1; the same
/// document for the serial and the distributed solve), the field file for ParaView and the
/// transient's history as CSV. Each file is written atomically. Units in the files: mm, mN, mJ, s.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "fem_reference/elasticity.hpp"
#include "fem_reference/hyperelastic.hpp"
#include "fem_reference/reference_checks.hpp"
#include "verification/scene.hpp"

namespace vessel {

/// The contact a run loaded: where, how and over what area.
struct ContactRecord {
  Vec3 point = Vec3::Zero();           ///< m
  Vec3 inward_normal = Vec3::Zero();   ///< unit, the direction the force pushes
  double radius = 0.0;                 ///< m
  double force = 0.0;                  ///< N
  double patch_area = 0.0;             ///< m²
  std::size_t patch_triangles = 0;
  Vec3 displacement = Vec3::Zero();    ///< m, at the contact point
};

/// The Richardson estimate at the contact point with the coarse level's facts.
struct RichardsonRecord {
  int coarse_level = 0;
  std::size_t coarse_dofs = 0;
  Vec3 direction = Vec3::Zero();
  fem::PointRichardson value;
};

/// The MPI decomposition of a distributed solve.
struct DistributedRecord {
  int ranks = 1;
  std::vector<std::size_t> tets_per_rank, dofs_per_rank;  ///< owned by each rank
  std::vector<std::size_t> local_tets_per_rank;           ///< held by each rank (owned and ghosts)
  std::vector<double> peak_memory_mb_per_rank;            ///< VmHWM at the end of the solve, MB
};

/// Everything one `fem` run reports.
/// A displacement read at one point along one direction, beside the linear reference's there.
struct QoiReading {
  Vec3 point = Vec3::Zero();      ///< m
  Vec3 direction = Vec3::Zero();  ///< unit: the patch's inward normal, else radial
  Vec3 displacement = Vec3::Zero(), linear_displacement = Vec3::Zero();  ///< m
};

struct FemRunRecord {
  VesselParams vessel;
  double youngs_modulus = 0.0, poisson_ratio = 0.0, density = 0.0;
  std::vector<std::string> loads;  ///< pressure | contact | gravity
  std::string ends;                ///< roller | clamped | clamped-inlet
  std::size_t mesh_nodes = 0, mesh_tets = 0;
  bool cache_hit = false;
  fem::ElasticityResult result;
  std::optional<ContactRecord> contact;
  std::optional<double> lame_error;  ///< relative L2 against Lamé's closed form
  std::optional<fem::ModalResult> modal;
  std::optional<RichardsonRecord> richardson;
  std::optional<fem::TransientOptions> transient_options;
  std::optional<fem::TransientResult> transient;
  std::optional<DistributedRecord> distributed;
  std::optional<QoiReading> finite_strain_qoi;  ///< --reference finite-strain
  double mesh_seconds = 0.0, output_seconds = 0.0;

  [[nodiscard]] double max_displacement() const;  ///< m, over the mesh nodes
};

/// The run as JSON text.
std::string fem_json(const FemRunRecord& run);
void write_fem_json(const std::filesystem::path& path, const FemRunRecord& run);
/// The finite-strain reference's run (`fem --reference finite-strain --json`; schema
/// "vesselverify.fem_finite_strain", version 1): the problem as fem_json gives it, the load factor
/// reached and why it stopped, load steps and Newton iterations, the largest displacement and the
/// contact point's (mm), the QoI reading (mm: the contact point along the inward normal, else the
/// scene's QoI point radially, beside the linear reference's), strain energy (mJ), the largest
/// principal Green–Lagrange strain, min J.
std::string finite_strain_json(const FemRunRecord& run, const fem::HyperelasticResult& result);
void write_finite_strain_json(const std::filesystem::path& path, const FemRunRecord& run,
                              const fem::HyperelasticResult& result);
/// Displacement and mode shapes at the nodes, strain and stress per tet (when the solve has them).
void write_fem_vtu(const std::filesystem::path& path, const TetMesh& mesh, const FemRunRecord& run);
/// The transient's probe displacement (mm) and energies (mJ) at every step.
void write_transient_csv(const std::filesystem::path& path, const fem::TransientResult& t);

}  // namespace vessel
