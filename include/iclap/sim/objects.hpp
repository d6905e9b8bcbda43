// SPDX-License-Identifier: MIT
#pragma once

// Objects of the simulated scene: a name (the class label) and a rigid shape
// resting on the table.

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "iclap/core/error.hpp"
#include "iclap/core/progress.hpp"
#include "iclap/core/utf8.hpp"
#include "iclap/data/csv_common.hpp"
#include "iclap/mesh/bvh.hpp"
#include "iclap/mesh/io_common.hpp"
#include "iclap/mesh/load.hpp"
#include "iclap/mesh/placement.hpp"

namespace iclap {

/// An object the simulator can explore. `shape` is in metres, in the
/// object's table frame: resting on the table plane z = 0 (no point below),
/// centred on x = y = 0. Cheap to copy (the BVH is shared).
struct SimObject {
  std::string name;  ///< class label written to the CSV (no commas or quotes)
  MeshBvh shape;
};

/// Makes a simulator object from a mesh in metres. With `place` (for meshes
/// in arbitrary file frames), the mesh is first put in a stable resting pose
/// by place_on_table; without it, it is only centred (for meshes built lying
/// on the table). Inside-out meshes are flipped. Throws InvalidArgument for
/// a name the CSV cannot hold or an invalid mesh.
namespace detail {
/// Throws InvalidArgument naming `argument` when `name` cannot be an object
/// name in the dataset CSV (object_name_problem).
inline void check_sim_object_name(const std::string& name, const std::string& argument) {
  const std::string problem = object_name_problem(name);
  if (!problem.empty()) throw InvalidArgument(argument, "object name '" + name + "' " + problem);
}
}  // namespace detail

inline SimObject make_sim_object(std::string name, TriangleMesh mesh_m, bool place = true) {
  detail::check_sim_object_name(name, "name");
  validate_mesh(mesh_m, "mesh of '" + name + "'");
  orient_outward(mesh_m);
  TablePlacement placed = place ? place_on_table(mesh_m) : center_on_table(std::move(mesh_m));
  return SimObject{std::move(name), MeshBvh(std::move(placed.mesh))};
}

namespace detail {

/// Just enough JSON to read a meshes.json manifest: values are parsed and
/// checked; only the top-level array's objects' "file" and
/// "scale_to_metres" members are kept. String escapes are decoded (\uXXXX
/// to UTF-8); an invalid one is a ParseError.
class ManifestParser {
 public:
  ManifestParser(std::string_view text, std::string name) : t_(text), name_(std::move(name)) {}

  std::map<std::string, double> parse() {
    std::map<std::string, double> scales;
    std::map<std::string, std::size_t> entry_lines;  // file -> line of its entry
    i_ = utf8_bom_length(t_);  // a byte-order mark, as an editor may write
    ws();
    expect('[');
    ws();
    if (peek() == ']') {
      ++i_;
    } else {
      for (;;) {
        ws();
        const std::size_t entry_line = line_;
        expect('{');
        std::optional<std::string> file;
        std::optional<double> scale;
        ws();
        if (peek() == '}') {
          ++i_;
        } else {
          for (;;) {
            ws();
            const std::size_t key_line = line_;
            const std::string key = string();
            ws();
            expect(':');
            ws();
            // A repeated member would silently override the first (JSON
            // leaves duplicate keys undefined), so the two read are unique.
            if ((key == "file" && file) || (key == "scale_to_metres" && scale))
              throw ParseError(name_, key_line, "'" + key + "' given twice in one entry");
            if (key == "file") file = string();
            else if (key == "scale_to_metres") scale = number();
            else skip_value();
            ws();
            if (peek() == ',') {
              ++i_;
              continue;
            }
            expect('}');
            break;
          }
        }
        if (file && scale) {
          if (!(*scale > 0)) throw ParseError(name_, entry_line, "scale_to_metres of '" + *file + "' must be positive");
          // A second entry for a file would silently override the first.
          const auto [at, added] = entry_lines.emplace(*file, entry_line);
          if (!added)
            throw ParseError(name_, entry_line,
                             "'" + *file + "' is listed twice (first at line " + std::to_string(at->second) + ")");
          scales[*file] = *scale;
        }
        ws();
        if (peek() == ',') {
          ++i_;
          continue;
        }
        expect(']');
        break;
      }
    }
    ws();
    if (i_ != t_.size()) fail("unexpected text after the top-level array");
    return scales;
  }

 private:
  char peek() const { return i_ < t_.size() ? t_[i_] : '\0'; }
  [[noreturn]] void fail(const std::string& why) const { throw ParseError(name_, line_, why); }
  void ws() {
    while (i_ < t_.size() && (t_[i_] == ' ' || t_[i_] == '\t' || t_[i_] == '\r' || t_[i_] == '\n')) {
      if (t_[i_] == '\n') ++line_;
      ++i_;
    }
  }
  void expect(char c) {
    if (peek() != c) fail(std::string("expected '") + c + "'");
    ++i_;
  }
  std::string string() {
    expect('"');
    std::string s;
    while (i_ < t_.size() && t_[i_] != '"') {
      if (t_[i_] == '\n') fail("line break inside a string");
      if (t_[i_] == '\\') {
        ++i_;
        if (i_ >= t_.size()) break;
        const char e = t_[i_];
        if (e == 'u') {
          // UTF-8, as the file names are (Python's json.dump writes every
          // non-ASCII character as \uXXXX, surrogate pairs beyond U+FFFF).
          std::uint32_t c = hex4();
          if (c >= 0xD800 && c <= 0xDBFF && t_.substr(i_ + 1, 2) == "\\u") {
            i_ += 2;
            const std::uint32_t low = hex4();
            if (low < 0xDC00 || low > 0xDFFF) fail("unpaired surrogate in a \\u escape");
            c = 0x10000 + ((c - 0xD800) << 10) + (low - 0xDC00);
          } else if (c >= 0xD800 && c <= 0xDFFF) {
            fail("unpaired surrogate in a \\u escape");
          }
          append_utf8(s, c);
        } else if (e == '"' || e == '\\' || e == '/') {
          s += e;
        } else if (e == 'n' || e == 't' || e == 'r' || e == 'b' || e == 'f') {
          s += e == 'n' ? '\n' : e == 't' ? '\t' : e == 'r' ? '\r' : e == 'b' ? '\b' : '\f';
        } else {
          fail("invalid escape " + quote_text(std::string{'\\', e}) + " in a string");
        }
        ++i_;
        continue;
      }
      s += t_[i_++];
    }
    expect('"');
    return s;
  }
  // The 4 hex digits after the 'u' at i_; leaves i_ on the last of them.
  std::uint32_t hex4() {
    if (i_ + 4 >= t_.size()) fail("truncated \\u escape");
    std::uint32_t c = 0;
    for (int k = 0; k < 4; ++k) {
      const char h = t_[++i_];
      if (!std::isxdigit(static_cast<unsigned char>(h))) fail("invalid \\u escape (4 hex digits expected)");
      c = c * 16 + static_cast<std::uint32_t>(h <= '9' ? h - '0' : (h | 0x20) - 'a' + 10);
    }
    return c;
  }
  double number() {
    const std::size_t start = i_;
    while (i_ < t_.size() && (std::isdigit(static_cast<unsigned char>(t_[i_])) || t_[i_] == '-' || t_[i_] == '+' ||
                              t_[i_] == '.' || t_[i_] == 'e' || t_[i_] == 'E'))
      ++i_;
    double v = 0;
    if (!token_to_double(t_.substr(start, i_ - start), v)) fail("expected a number");
    return v;
  }
  /// Deepest nesting of arrays and objects skip_value accepts (it recurses).
  static constexpr int kMaxDepth = 256;

  void skip_value(int depth = 2) {  // inside the top-level array's object
    const char c = peek();
    if (c == '"') {
      string();
    } else if (c == '{' || c == '[') {
      if (depth >= kMaxDepth) fail("nesting deeper than " + std::to_string(kMaxDepth));
      const char close = c == '{' ? '}' : ']';
      ++i_;
      ws();
      if (peek() == close) {
        ++i_;
        return;
      }
      for (;;) {
        ws();
        if (c == '{') {
          string();
          ws();
          expect(':');
          ws();
        }
        skip_value(depth + 1);
        ws();
        if (peek() == ',') {
          ++i_;
          continue;
        }
        expect(close);
        return;
      }
    } else if (t_.substr(i_, 4) == "true" || t_.substr(i_, 4) == "null") {
      i_ += 4;
    } else if (t_.substr(i_, 5) == "false") {
      i_ += 5;
    } else {
      number();
    }
  }

  std::string_view t_;
  std::string name_;
  std::size_t i_ = 0;
  std::size_t line_ = 1;
};

}  // namespace detail

/// Reads a meshes.json manifest (a JSON array of objects with "file" and
/// "scale_to_metres", as in the team's shared mesh folder): file name ->
/// metres per file unit. Entries without both members are ignored; a file
/// with two such entries, or an entry with either member twice, is a
/// ParseError at the second. A UTF-8 byte-order mark is skipped. Throws
/// IoError / ParseError(file, line, reason).
inline std::map<std::string, double> read_mesh_manifest(const std::string& path) {
  return detail::ManifestParser(detail::read_file(path), path).parse();
}

/// Loads every .obj, .stl and .ply file of `dir` (not recursive, sorted by
/// file name) as a simulator object named after the file's stem, scaled to
/// metres and put in its stable resting pose (place_on_table).
///
/// `unit` is the unit of every file; without it (automatic), each file's
/// `scale_to_metres` is taken from `dir`/meshes.json, and a file it does not
/// list is an InvalidArgument that names it. Throws InvalidArgument if the
/// folder holds no mesh or two files share a stem, IoError/ParseError for
/// unreadable or malformed files. `progress` counts loaded files.
inline std::vector<SimObject> load_mesh_objects(const std::string& dir, std::optional<LengthUnit> unit = std::nullopt,
                                                const ProgressCallback& progress = {}) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw IoError(dir, "is not a directory");
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(dir, ec))
    if (entry.is_regular_file() && is_mesh_file(entry.path().string())) files.push_back(entry.path());
  if (ec) throw IoError(dir, "cannot list: " + ec.message());
  std::sort(files.begin(), files.end());
  if (files.empty()) throw InvalidArgument("dir", "'" + dir + "' holds no .obj, .stl or .ply file");
  std::map<std::string, double> manifest;
  const std::string manifest_path = (fs::path(dir) / "meshes.json").string();
  if (!unit) {
    if (!fs::exists(manifest_path))
      throw InvalidArgument("unit", "automatic units need " + manifest_path + " (or give the unit: m or mm)");
    manifest = read_mesh_manifest(manifest_path);
  }
  std::vector<SimObject> objects;
  std::map<std::string, std::string> stems;
  for (std::size_t i = 0; i < files.size(); ++i) {
    const std::string path = files[i].string();
    const std::string stem = files[i].stem().string();
    if (!stems.emplace(stem, path).second)
      throw InvalidArgument("dir", "two meshes are named '" + stem + "': " + stems[stem] + " and " + path);
    double scale = 1.0;
    if (unit) {
      scale = metres_per_unit(*unit);
    } else {
      const auto it = manifest.find(files[i].filename().string());
      if (it == manifest.end())
        throw InvalidArgument("unit", path + " is not listed in " + manifest_path + " (give the unit: m or mm)");
      scale = it->second;
    }
    TriangleMesh mesh = load_mesh(path);
    scale_mesh(mesh, scale);
    try {
      objects.push_back(make_sim_object(stem, std::move(mesh), true));
    } catch (const InvalidArgument& e) {  // e.g. a flat mesh, a name with a comma
      throw InvalidArgument(path, e.what());
    }
    if (progress) progress(i + 1, files.size());
  }
  return objects;
}

}  // namespace iclap
