// SPDX-License-Identifier: MIT
// Reproducer of session 58's audit of include/iclap/core/error.hpp:
// rename_argument and rename_argument_prefix with errors derived from
// InvalidArgument. It failed on the code it was written against; its comment
// says what happened before ("Was").

#include <doctest/doctest.h>

#include <string>
#include <typeinfo>

#include "iclap/core/error.hpp"

using iclap::DimensionMismatch;
using iclap::EmptyInput;
using iclap::InvalidArgument;
using iclap::NonFiniteValue;

namespace {

// The dynamic type's name and what() of the InvalidArgument `f` throws.
template <typename F>
std::string caught(F&& f) {
  try {
    f();
  } catch (const InvalidArgument& e) {
    const char* type = typeid(e) == typeid(EmptyInput)          ? "EmptyInput"
                       : typeid(e) == typeid(DimensionMismatch) ? "DimensionMismatch"
                       : typeid(e) == typeid(NonFiniteValue)    ? "NonFiniteValue"
                       : typeid(e) == typeid(InvalidArgument)   ? "InvalidArgument"
                                                                : "other";
    return std::string(type) + " " + e.what();
  }
  return "none";
}

}  // namespace

// Input: a callee of rename_argument("image", "images[3]", ...) (or of
// rename_argument_prefix) throws EmptyInput, DimensionMismatch or
// NonFiniteValue naming "image".
// Was: they passed through unrenamed ("image: is empty"): only an
// InvalidArgument of exactly that type was renamed (a rethrow of the base
// would have sliced the others), so extract_features named a descriptor's
// DimensionMismatch "image", a parameter its caller never passed.
// Now: the error is thrown again with its own type, data and reason, naming
// the new argument.
TEST_CASE("audit: rename_argument renames derived errors and keeps their type and data") {
  CHECK(caught([] { iclap::rename_argument("image", "images[3]", [] { throw EmptyInput("image"); }); }) ==
        "EmptyInput images[3]: is empty");
  CHECK(caught([] {
          iclap::rename_argument("image", "images[3]", [] { throw DimensionMismatch("image", 84, 83); });
        }) == "DimensionMismatch images[3]: has dimension 83, expected 84");
  CHECK(caught([] {
          iclap::rename_argument("points", "mesh", [] { throw NonFiniteValue("points", 2, 7, 1.0 / 0.0); });
        }) == "NonFiniteValue mesh: non-finite value inf at row 2, column 7");
  CHECK(caught([] {
          iclap::rename_argument_prefix("settings.", "settings.search.",
                                        [] { throw EmptyInput("settings.points", "holds no point"); });
        }) == "EmptyInput settings.search.points: holds no point");
  // The data of the derived type and the reason go with it.
  try {
    iclap::rename_argument("image", "images[3]", [] { throw DimensionMismatch("image", 84, 83); });
    FAIL("nothing thrown");
  } catch (const DimensionMismatch& e) {
    CHECK(e.argument() == "images[3]");
    CHECK(e.reason() == "has dimension 83, expected 84");
    CHECK(e.expected() == 84);
    CHECK(e.actual() == 83);
  }
  try {
    iclap::rename_argument("points", [] { return std::string("mesh"); },
                           [] { throw NonFiniteValue("points", 2, 7, 0.0 / 0.0); });
    FAIL("nothing thrown");
  } catch (const NonFiniteValue& e) {
    CHECK(e.argument() == "mesh");
    CHECK(e.row() == 2);
    CHECK(e.column() == 7);
  }
  // Nested renames, and other names, as for a plain InvalidArgument.
  CHECK(caught([] {
          iclap::rename_argument("b", "c", [] { iclap::rename_argument("a", "b", [] { throw EmptyInput("a"); }); });
        }) == "EmptyInput c: is empty");
  CHECK(caught([] { iclap::rename_argument("image", "images[3]", [] { throw EmptyInput("points"); }); }) ==
        "EmptyInput points: is empty");
}
