#pragma once
/// One model's deformed wall as report.html draws it in 3D, read from the VTU of fields that
/// `vesselverify run` writes per case and names in results.json (displacement_model_m,
/// displacement_reference_m, error_magnitude_mm at the model's nodes), reduced to what is drawn:
/// the boundary faces of a tet mesh, a surface network's triangles, else its springs as lines,
/// and only their nodes.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "meshes/vtu_io.hpp"

namespace vessel::reports {

struct WallView {
  std::string model, kind;  ///< kind: the outcome's (fem, volume_msm, surface_msm, ...)
  int level = 0;            ///< the model's mesh level (−1: a wall that is not one level's)
  double poisson_ratio = 0.0, magnitude = 0.0;
  bool lines = false;  ///< springs as line segments (a network without faces); else triangles
  bool network_faces = false;  ///< the triangles are a surface network's own (their edges: springs)
  std::vector<float> rest_mm;         ///< x, y, z per drawn node, mm
  std::vector<float> u_model_mm;      ///< the model's displacement per drawn node, mm
  std::vector<float> u_reference_mm;  ///< the reference's displacement at the same nodes, mm
  std::vector<std::uint32_t> indices;  ///< 3 per triangle or 2 per line, into the drawn nodes
  /// The coloured quantity per drawn node (|error| in mm for a model's wall; the scene's views
  /// name it and its unit, SceneViews) quantised: value ≈ colour_code · colour_step (rounded to
  /// nearest, so within half a step of the value).
  std::vector<std::uint16_t> colour_code;
  double colour_step = 0.0;
  double colour_max = 0.0;  ///< the largest value over the drawn nodes
};

/// Sets v's colour_code, colour_step and colour_max from one value per drawn node.
void set_colour(WallView& v, const std::vector<double>& values);

/// The drawn part of a VTU as above. InputError naming `source` when a field is missing or the
/// cells are of a type the view cannot draw.
WallView wall_view(const VtuData& vtu, const std::string& source);

/// Faces of a tet mesh that belong to one tet only (its boundary), each wound so that its normal
/// (right-hand rule) points out of its tet, whatever the tet's own orientation; `connectivity`
/// holds 4 indices into `points` per tet.
std::vector<std::uint32_t> boundary_faces(const std::vector<std::size_t>& connectivity,
                                          const std::vector<Vec3>& points);

/// RFC 4648 base64 of raw bytes (the page decodes typed arrays from it) and its inverse
/// (InputError on a character outside the alphabet).
std::string base64_encode(const void* data, std::size_t bytes);
std::vector<std::uint8_t> base64_decode(const std::string& text);

}  // namespace vessel::reports
