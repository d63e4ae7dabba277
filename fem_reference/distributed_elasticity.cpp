/// deal.II/MPI implementation of the distributed FEM reference: the MPI session, the mesh sent from
/// rank 0, and the solver's triangulation, displacement system (CG-AMG) and post-processing. Rank 0
/// partitions the serial mesh with METIS and sends each rank its part plus one ghost layer, kept
/// in a parallel::fullydistributed::Triangulation; assembly into Trilinos matrices as in
/// step-40. The mixed system is in distributed_mixed.cpp, what rank 0 gathers in
/// distributed_gather.cpp. The validation, boundary tagging, constraints, element integrals, AMG and
/// post-processing are the serial solver's own (detail/), so one rank, many ranks and the serial
/// solver solve the same discrete system.
#include "fem_reference/distributed_elasticity.hpp"

#include <deal.II/base/index_set.h>
#include <deal.II/base/mpi.h>
#include <deal.II/distributed/fully_distributed_tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/tria.h>
#include <deal.II/grid/tria_description.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

#include "fem_reference/detail/amg.hpp"
#include "fem_reference/detail/boundary.hpp"
#include "fem_reference/detail/byte_buffer.hpp"
#include "fem_reference/detail/constraints.hpp"
#include "fem_reference/detail/distributed_solver.hpp"
#include "fem_reference/detail/matrix_free_elasticity.hpp"
#include "fem_reference/detail/memory_probe.hpp"
#include "fem_reference/detail/postprocess.hpp"
#include "fem_reference/detail/serial_solver.hpp"
#include "fem_reference/detail/validation.hpp"
#include "fem_reference/detail/weak_form.hpp"
#include "meshes/foundation/errors.hpp"

namespace vessel::fem {

namespace dl = dealii;
using detail::kDim;

// ---------------------------------------------------------------------------------------------
// MPI session

struct MpiSession::Impl {
  int argc = 1;
  char name[16] = "vesselverify";
  char* argv_storage[2] = {name, nullptr};
  char** argv = argv_storage;
  std::unique_ptr<dl::Utilities::MPI::MPI_InitFinalize> mpi;
};

MpiSession::MpiSession() : impl_(std::make_unique<Impl>()) {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (initialized) {
    throw std::logic_error("MpiSession: MPI is already initialised in this process");
  }
  // One thread per rank: the ranks are the parallelism (the machines have few cores).
  impl_->mpi = std::make_unique<dl::Utilities::MPI::MPI_InitFinalize>(impl_->argc, impl_->argv, 1);
}

MpiSession::~MpiSession() = default;

int MpiSession::rank() const {
  return static_cast<int>(dl::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD));
}
int MpiSession::size() const {
  return static_cast<int>(dl::Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD));
}

// ---------------------------------------------------------------------------------------------
// Mesh broadcast

namespace {

std::vector<char> pack_mesh(const TetMesh& m) {
  detail::ByteWriter w;
  detail::write_mesh(w, m);
  return std::move(w.bytes);
}

TetMesh unpack_mesh(const std::vector<char>& bytes) {
  detail::ByteReader r{bytes};
  return detail::read_mesh(r);
}

}  // namespace

void run_on_rank0(const std::function<void()>& work) { detail::run_on_root(MPI_COMM_WORLD, work); }

std::vector<int> broadcast_from_rank0(std::vector<int> values) {
  std::uint64_t n = values.size();
  MPI_Bcast(&n, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
  values.resize(n);
  MPI_Bcast(values.data(), static_cast<int>(n), MPI_INT, 0, MPI_COMM_WORLD);
  return values;
}

TetMesh make_mesh_on_rank0(const std::function<TetMesh()>& make) {
  const MPI_Comm comm = MPI_COMM_WORLD;
  const unsigned rank = dl::Utilities::MPI::this_mpi_process(comm);
  TetMesh mesh;
  detail::run_on_root(comm, [&] { mesh = make(); });
  std::vector<char> bytes;
  if (rank == 0) bytes = pack_mesh(mesh);
  detail::broadcast_bytes(bytes, 0, comm);
  if (rank != 0) mesh = unpack_mesh(bytes);
  return mesh;
}

// ---------------------------------------------------------------------------------------------
// The distributed solver

namespace {

/// InputError (the same on every rank) for what the distributed solver does not do: curved
/// surfaces and the direct solver.
void validate_distributable(const ElasticityProblem& p) {
  std::ostringstream msg;
  if (!p.curved_surfaces.empty()) {
    msg << "the distributed (MPI) solver has straight-sided (affine) tets only; curved surfaces "
           "(--curved) need the serial solver";
  } else if (p.options.solver == LinearSolver::direct) {
    msg << "the distributed (MPI) solver is iterative (CG with algebraic multigrid or the "
           "matrix-free p-multigrid, FGMRES with the block preconditioner for the mixed system); "
           "solver 'direct' is serial only: use auto, cg-amg, matrix-free or gmres-block";
  } else if (p.options.solver == LinearSolver::matrix_free && detail::uses_mixed_formulation(p)) {
    msg << "solver matrix-free is for the displacement system (P1, P2); the mixed (Taylor-Hood) "
           "system needs gmres-block";
  }
  if (!msg.str().empty()) throw InputError(msg.str());
}

}  // namespace

namespace detail {

SolverChoice distributed_displacement_solver(const SolverOptions& o, std::size_t n_dofs,
                                             int degree) {
  // The serial rule where it picks the matrix-free solve; CG-AMG where it would factorise.
  const SolverChoice serial = chosen_solver(o, {false, n_dofs, degree, false, true});
  if (serial.solver == LinearSolver::matrix_free || serial.solver == LinearSolver::cg_amg) {
    return serial;
  }
  return {LinearSolver::cg_amg, serial.reason +
                                    "; the distributed solver has no direct "
                                    "solve: CG with AMG"};
}

using CellIt = CellIterator;

Distributed::Distributed(const TetMesh& mesh, const ElasticityProblem& problem, MPI_Comm comm)
    : input_(mesh),
      input_problem_(problem),
      comm_(comm),
      rank_(dl::Utilities::MPI::this_mpi_process(comm)),
      n_ranks_(dl::Utilities::MPI::n_mpi_processes(comm)),
      linear_(1),
      mapping_(linear_),
      tria_(comm) {}

double Distributed::max_over_ranks(double v) const { return dl::Utilities::MPI::max(v, comm_); }

Vec3 Distributed::sum_over_ranks(const Vec3& v) const {
  Vec3 s;
  for (int c = 0; c < 3; ++c) s[c] = dl::Utilities::MPI::sum(v[c], comm_);
  return s;
}

void Distributed::build_triangulation(const DistributedOptions& options) {
  // Rank 0 alone builds the serial coarse triangulation (the cells in TetMesh order, so a cell's
  // coarse cell id is its tet index) and partitions it with METIS; each rank receives the
  // description of its own cells and ghosts (one group of all ranks). The serial triangulation
  // lives only inside this call.
  std::vector<unsigned> owner;  // rank 0: per tet, its rank
  {
    const auto description =
        dl::TriangulationDescription::Utilities::create_description_from_triangulation_in_groups<
            kDim, kDim>(
            [&](dl::Triangulation<kDim>& serial) { create_coarse_triangulation(input_, serial); },
            [&](dl::Triangulation<kDim>& serial, const MPI_Comm& comm, unsigned) {
              dl::GridTools::partition_triangulation(dl::Utilities::MPI::n_mpi_processes(comm),
                                                     serial);
              owner.resize(serial.n_active_cells());
              for (const auto& cell : serial.active_cell_iterators())
                owner[cell->active_cell_index()] = cell->subdomain_id();
              report_memory(static_cast<int>(rank_), "serial triangulation partitioned");
            },
            comm_, static_cast<int>(n_ranks_));
    tria_.create_triangulation(description);
  }
  release_free_memory();
  report_memory(static_cast<int>(rank_), "distributed triangulation");
  // Then each rank's part of the mesh and problem, cut by rank 0 along the same partition.
  const bool mixed = rank_ == 0 && uses_mixed_formulation(input_problem_);
  part_ = distribute_parts(input_, input_problem_, owner, options, mixed, comm_);
  std::vector<unsigned>().swap(owner);
  mixed_ = part_.mixed;
  degree_ = mixed_ ? 2 : problem_.options.degree;
  mesh_map_ = match_and_tag_boundary(tria_, mesh_, part_.global_tet);
  release_free_memory();
  report_memory(static_cast<int>(rank_), "mesh part received");
}

void Distributed::release_system() {
  matrix_.clear();
  block_matrix_.clear();
  schur_.clear();
  rhs_.clear();
  block_rhs_.reinit(0);
  solution_.clear();
  release_free_memory();
}

void Distributed::support_constraints(const dl::DoFHandler<kDim>& dof,
                                      dl::AffineConstraints<double>& constraints) const {
  dl::IndexSet relevant;
  dl::DoFTools::extract_locally_relevant_dofs(dof, relevant);
  constraints.clear();
  constraints.reinit(relevant);
  add_point_constraints(mesh_, problem_.point_constraints, dof, mesh_map_.vertex_node, constraints);
  add_dirichlet_constraints(mesh_, problem_.dirichlet, mapping_, dof, constraints);
  constraints.close();
}

void Distributed::setup_dofs() {
  fe_ = make_element(degree_, mixed_);
  dof_.reinit(tria_);
  dof_.distribute_dofs(*fe_);
  if (mixed_) {
    setup_mixed_system();
    return;
  }
  owned_ = dof_.locally_owned_dofs();
  dl::DoFTools::extract_locally_relevant_dofs(dof_, relevant_);
  support_constraints(dof_, constraints_);
  rhs_.reinit(owned_, comm_);
  solution_.reinit(owned_, comm_);
  ghosted_.reinit(owned_, relevant_, comm_);
  const SolverChoice choice =
      distributed_displacement_solver(problem_.options, dof_.n_dofs(), degree_);
  out_.fem.solver = choice.solver;
  out_.fem.solver_reason = choice.reason;
  matrix_free_ = choice.solver == LinearSolver::matrix_free;
  if (matrix_free_) return;  // no matrix

  // step-40's distributed sparsity pattern.
  dl::DynamicSparsityPattern dsp(relevant_);
  dl::DoFTools::make_sparsity_pattern(dof_, dsp, constraints_, false);
  dl::SparsityTools::distribute_sparsity_pattern(dsp, owned_, comm_, relevant_);
  matrix_.reinit(owned_, owned_, dsp, comm_);
}

void Distributed::assemble() {
  if (mixed_) {
    assemble_mixed();
    return;
  }
  if (matrix_free_) {
    const Vec3 applied = assemble_load_vector(*form_, mapping_, dof_, degree_, constraints_, rhs_);
    rhs_.compress(dl::VectorOperation::add);
    out_.fem.applied_load = sum_over_ranks(applied);
    return;
  }
  assemble_into(matrix_, rhs_);
}

void Distributed::solve_linear() {
  if (mixed_) {
    solve_mixed();
    return;
  }
  if (matrix_free_) {
    solve_matrix_free();
    return;
  }
  const auto& o = problem_.options;
  const double rhs_norm = rhs_.l2_norm();
  solution_ = 0.0;
  if (rhs_norm > 0.0) {
    // Rotations about the mesh's node centroid, the same point on every rank.
    dl::TrilinosWrappers::PreconditionAMG amg;
    std::vector<double> modes_storage;  // must outlive amg
    initialize_elasticity_amg(amg, matrix_, displacement_rows(mapping_, dof_, owned_),
                              part_.centroid, degree_ > 1, o.amg_rigid_body_modes,
                              AmgProlongator::plain, modes_storage);
    release_free_memory();  // ML's set-up temporaries
    report_memory(static_cast<int>(rank_), "AMG hierarchy built");
    dl::SolverControl control(o.max_iterations, o.cg_relative_tolerance * rhs_norm);
    dl::SolverCG<VectorT> cg(control);
    try {
      cg.solve(matrix_, solution_, rhs_, amg);
    } catch (const dl::SolverControl::NoConvergence& e) {
      std::ostringstream m;
      m << "distributed CG with AMG did not converge in " << e.last_step << " iterations (residual "
        << e.last_residual << ", target " << o.cg_relative_tolerance * rhs_norm
        << "): raise --max-iterations or --tolerance";
      throw std::runtime_error(m.str());
    }
    out_.fem.iterations = control.last_step();
  }
  constraints_.distribute(solution_);
  ghosted_ = solution_;
}

void Distributed::solve_matrix_free() {
  const auto& o = problem_.options;
  solution_ = 0.0;
  if (rhs_.l2_norm() > 0.0) {
    PMultigridSettings settings;  // ML-CG on P1: CHOLMOD is serial
    const MatrixFreeElasticitySolver wall(
        mapping_, dof_,
        [this](const dl::DoFHandler<kDim>& d, dl::AffineConstraints<double>& c) {
          support_constraints(d, c);
        },
        degree_, form_->lambda(), form_->mu(), part_.centroid, settings);
    report_memory(static_cast<int>(rank_), "matrix-free operator and p-multigrid set up");
    MfVector b, u;
    wall.initialize_dof_vector(b);
    wall.initialize_dof_vector(u);
    for (const auto i : owned_) b[i] = rhs_[i];
    out_.fem.iterations = wall.solve(b, u, o.cg_relative_tolerance, o.max_iterations).iterations;
    out_.fem.matrix_free = wall.profile();
    for (const auto i : owned_) solution_[i] = u[i];
    solution_.compress(dl::VectorOperation::insert);
  }
  constraints_.distribute(solution_);
  ghosted_ = solution_;
}

VectorT Distributed::residual(StrainSummary& strain) const {
  // Energy and principal strains at the assembly quadrature points; residual K u − f of the
  // unconstrained system for the support reactions (as the serial solver computes them).
  CellValues values(mapping_, *fe_, degree_);
  dl::Vector<double> r_local;
  std::vector<dl::types::global_dof_index> dofs;
  VectorT r(owned_, comm_);
  for (const auto& cell : dof_.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    element_residual(*form_, cell, values, ghosted_, dofs, r_local);  // values.cell on cell
    add_cell_strain(*form_, values.cell, ghosted_, strain);
    r.add(dofs, r_local);
  }
  r.compress(dl::VectorOperation::add);
  return r;
}

void Distributed::postprocess() {
  auto& r = out_.fem;
  gather_nodal_displacement();
  StrainSummary strain;
  const VectorT res = residual(strain);
  r.strain_energy = dl::Utilities::MPI::sum(strain.energy, comm_);
  r.max_principal_strain = dl::Utilities::MPI::max(strain.max_principal, comm_);
  r.max_abs_principal_strain = dl::Utilities::MPI::max(strain.max_abs_principal, comm_);

  // Reactions: the residual summed over each group's constrained owned DoFs (point constraints on
  // the group included), found from the faces of owned and ghost cells.
  r.reactions.clear();
  std::vector<std::string> seen;
  for (const auto& bc : problem_.dirichlet) {
    if (std::find(seen.begin(), seen.end(), bc.group) != seen.end()) continue;
    seen.push_back(bc.group);
    const Vec3 mine =
        group_reaction(dof_, constraints_, group_boundary_id(mesh_, bc.group), owned_, res);
    r.reactions.push_back({bc.group, sum_over_ranks(mine)});
  }
}

DistributedResult Distributed::run(const DistributedOptions& options) {
  auto& r = out_.fem;
  out_.n_ranks = static_cast<int>(n_ranks_);
  const int rank = static_cast<int>(rank_);
  report_memory(rank, "start");
  auto t0 = Clock::now();
  build_triangulation(options);
  r.element = mixed_ ? "P2-P1 (Taylor-Hood)" : (degree_ == 1 ? "P1" : "P2");
  r.formulation = mixed_ ? Formulation::mixed : Formulation::displacement;
  form_ = std::make_unique<WeakForm>(mesh_, problem_, mixed_, mesh_map_);
  setup_dofs();
  release_free_memory();  // the sparsity pattern's pages, before the AMG set-up's peak
  r.n_dofs = dof_.n_dofs();
  r.timings.setup = max_over_ranks(seconds_since(t0));
  report_memory(rank, "DoFs, sparsity and matrix set up");

  std::size_t owned_cells = 0;
  for (const auto& cell : tria_.active_cell_iterators()) owned_cells += cell->is_locally_owned();
  const auto all = [&](std::size_t mine) {
    const auto v = dl::Utilities::MPI::all_gather(comm_, mine);
    return std::vector<std::size_t>(v.begin(), v.end());
  };
  out_.cells_per_rank = all(owned_cells);
  out_.dofs_per_rank = all(static_cast<std::size_t>(owned_.n_elements()));
  out_.local_tets_per_rank = all(mesh_.tets.size());

  t0 = Clock::now();
  assemble();
  r.timings.assembly = max_over_ranks(seconds_since(t0));
  report_memory(rank, "assembled");
  t0 = Clock::now();
  solve_linear();
  r.timings.solve = max_over_ranks(seconds_since(t0));
  report_memory(rank, "solved");
  release_system();
  t0 = Clock::now();
  postprocess();
  out_.point_displacement = evaluate(out_.point_rank);
  if (part_.serial_dofs) out_.serial_dofs = gather_serial_dofs();
  r.timings.postprocess = max_over_ranks(seconds_since(t0));
  report_memory(rank, "post-processed and gathered");
  out_.peak_memory_per_rank = all(memory_use().peak);
  return std::move(out_);
}

}  // namespace detail

DistributedResult solve_elasticity_distributed(const TetMesh& mesh,
                                               const ElasticityProblem& problem,
                                               const DistributedOptions& options) {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (!initialized) {
    throw std::logic_error(
        "solve_elasticity_distributed needs MPI: create a fem::MpiSession first");
  }
  const MPI_Comm comm = options.self_only ? MPI_COMM_SELF : MPI_COMM_WORLD;
  // Only rank 0 has the mesh to check the problem against: its InputError reaches every rank.
  detail::run_on_root(comm, [&] {
    detail::validate_problem(mesh, problem);
    validate_distributable(problem);
  });
  detail::Distributed solver(mesh, problem, comm);
  return solver.run(options);
}

}  // namespace vessel::fem
