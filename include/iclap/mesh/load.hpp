// SPDX-License-Identifier: MIT
#pragma once

// Loading a mesh file by its extension, and length units.

#include <algorithm>
#include <cctype>
#include <cmath>
#include <string>

#include "iclap/core/error.hpp"
#include "iclap/mesh/obj.hpp"
#include "iclap/mesh/ply.hpp"
#include "iclap/mesh/stl.hpp"
#include "iclap/mesh/triangle_mesh.hpp"

namespace iclap {

/// Length unit of a mesh file's coordinates.
enum class LengthUnit {
  metres,
  millimetres,
};

/// Metres per unit: 1 or 0.001.
inline double metres_per_unit(LengthUnit u) { return u == LengthUnit::millimetres ? 1e-3 : 1.0; }

/// "m" -> metres, "mm" -> millimetres; InvalidArgument naming `argument` otherwise.
inline LengthUnit parse_length_unit(const std::string& text, const std::string& argument = "unit") {
  if (text == "m") return LengthUnit::metres;
  if (text == "mm") return LengthUnit::millimetres;
  throw InvalidArgument(argument, quote_text(text, 40) + " is not a length unit (expected m or mm)");
}

/// The lower-case extension of `path` with its dot (".obj"), or "".
inline std::string mesh_extension(const std::string& path) {
  const auto slash = path.find_last_of("/\\");
  const auto dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return {};
  std::string ext = path.substr(dot);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

/// True for the extensions load_mesh reads: .obj, .stl, .ply (any case).
inline bool is_mesh_file(const std::string& path) {
  const std::string ext = mesh_extension(path);
  return ext == ".obj" || ext == ".stl" || ext == ".ply";
}

/// Loads an OBJ, STL or PLY mesh chosen by the file's extension (any case),
/// in file units. Throws InvalidArgument for another extension, IoError if
/// the file cannot be read and ParseError (file, line or byte offset, reason)
/// for malformed content.
inline TriangleMesh load_mesh(const std::string& path) {
  const std::string ext = mesh_extension(path);
  if (ext == ".obj") return load_obj(path);
  if (ext == ".stl") return load_stl(path);
  if (ext == ".ply") return load_ply(path);
  throw InvalidArgument("path", quote_text(path) + " has no mesh extension (expected .obj, .stl or .ply)");
}

/// Multiplies every vertex by `factor` (e.g. metres_per_unit(unit)). Throws
/// InvalidArgument naming "factor" unless it is finite and positive (NaN
/// gave a mesh of NaN, a negative factor one turned inside out, zero one
/// collapsed to a point).
inline void scale_mesh(TriangleMesh& mesh, double factor) {
  if (!(std::isfinite(factor) && factor > 0))
    throw InvalidArgument("factor", "must be finite and positive, got " + format_value(factor));
  mesh.vertices *= factor;
}

}  // namespace iclap
