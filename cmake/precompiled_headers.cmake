# Precompiled headers: the third-party headers that most sources of a target parse again and again
# (Eigen, deal.II, GoogleTest, nlohmann/json, CLI11) are compiled once per target instead of once
# per source. Only targets with several sources get one: building the header costs about as much as
# compiling one source. ccache caches sources compiled with a precompiled header
# (compiler_cache.cmake sets the sloppiness that needs). Off: -DVESSEL_PCH=OFF.
# docs/measurements/build_times.md has what they buy (scripts/measure_build_times.py).
option(VESSEL_PCH "Precompile the heaviest third-party headers of the larger targets" ON)

set(VESSEL_PCH_EIGEN <Eigen/Core> <Eigen/Geometry> <Eigen/SparseCore> <vector> <string> <memory>
    <functional> <algorithm> <optional> <map> <filesystem>)
set(VESSEL_PCH_DEALII
    <deal.II/base/quadrature_lib.h> <deal.II/dofs/dof_handler.h> <deal.II/dofs/dof_tools.h>
    <deal.II/fe/fe_simplex_p.h> <deal.II/fe/fe_system.h> <deal.II/fe/fe_values.h>
    <deal.II/fe/mapping_fe.h> <deal.II/grid/tria.h> <deal.II/lac/affine_constraints.h>
    <deal.II/lac/dynamic_sparsity_pattern.h> <deal.II/lac/sparse_matrix.h> <deal.II/lac/vector.h>)
set(VESSEL_PCH_JSON <nlohmann/json.hpp>)
set(VESSEL_PCH_CLI <CLI/CLI.hpp>)
set(VESSEL_PCH_GTEST <gtest/gtest.h>)

# vessel_precompile(target HEADERS...): every source of the target starts from these headers.
function(vessel_precompile target)
  if(VESSEL_PCH)
    target_precompile_headers(${target} PRIVATE ${ARGN})
  endif()
endfunction()
