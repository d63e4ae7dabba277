#pragma once
/// What every model run shares once it has its displacements: where its answer is read (the QoI
/// node, the wall line), the outcome's errors and budget figures filled against the reference,
/// and the VTU fields written for ParaView and the report.
#include <filesystem>
#include <vector>

#include <Eigen/Core>

#include "meshes/vtu_io.hpp"
#include "msm/form/form.hpp"
#include "msm/topology/springs.hpp"
#include "verification/harness/options.hpp"
#include "verification/harness/outcome.hpp"
#include "verification/harness/references.hpp"
#include "verification/scene.hpp"

namespace vessel {

inline constexpr int kHistorySamples = 200;  ///< points kept of a dynamic model's QoI history

/// u scaled by `factor`.
std::vector<Vec3> scaled(const std::vector<Vec3>& u, double factor);

/// Unknowns of a problem: its free dofs.
std::size_t free_unknowns(const msm::Problem& p);

/// A flat per-dof vector (x0, y0, z0, x1, ...) as one Vec3 per node.
std::vector<Vec3> per_node(const Eigen::VectorXd& v);

/// Node displacements x − rest, m.
std::vector<Vec3> displacements(const Eigen::VectorXd& x, const std::vector<Vec3>& nodes);

/// Where a model's results are read: the QoI node and the wall line.
struct ReadOut {
  std::size_t qoi = 0;
  std::vector<std::size_t> wall_line;
};

/// The QoI node and, for a parametric vessel, the wall line through the QoI point.
ReadOut read_out(const Scene& s, int level, const std::vector<Vec3>& nodes, const Vec3& qoi);

/// Fills `out` from the model's displacements `u_model` at `nodes` against the reference `ref`
/// (unit load, scaled by `magnitude`): the budget quantities and time per update, the wall
/// profile, the nodal statistics and the reference's uncertainty, the QoI displacements and the
/// linear-regime flag; marks the outcome ok. `loads` the nodal loads (contact only), `steps` and
/// `dt` the run's (0 for static solvers).
void finish_outcome(ModelOutcome& out, const Scene& s, const std::vector<Vec3>& nodes,
                    const std::vector<Vec3>& u_model, const ReferenceAtPoints& ref,
                    double magnitude, const ReadOut& at, double ref_max_strain_unit,
                    const Vec3& qoi_point, const std::vector<Vec3>& loads, long steps, double dt);

/// Fields are written at one load per model: the budget's (when the run includes it), else the
/// largest within the linear regime, else the smallest.
bool wants_fields(const HarnessOptions& o, const Scene& s, double magnitude,
                  double ref_max_strain_unit);

/// Where write_model_fields writes an outcome's fields, relative to the fields directory.
std::filesystem::path fields_file(const Scene& s, const ModelOutcome& out);

/// A model's displacement fields against a reference's, for ParaView and the report's 3D view:
/// points at the model's rest nodes (m), displacement_model_m, displacement_reference_m and
/// error_m in m (so that "Warp By Vector" at scale 1 shows the deformed state), and
/// error_magnitude_mm. Creates the file's folder.
void write_fields_vtu(const std::filesystem::path& path, const std::vector<Vec3>& nodes,
                      const VtuCells& cells, const std::vector<Vec3>& u_model,
                      const std::vector<Vec3>& u_ref);

/// write_fields_vtu of one outcome at o.fields_dir / fields_file(s, out).
void write_model_fields(const HarnessOptions& o, const Scene& s, const ModelOutcome& out,
                        const std::vector<Vec3>& nodes, const VtuCells& cells,
                        const std::vector<Vec3>& u_model, const std::vector<Vec3>& u_ref);

/// A mass-spring network's cells: its tets (volume), triangles (surface), else its springs.
VtuCells network_cells(const msm::SpringNetwork& n);

}  // namespace vessel
