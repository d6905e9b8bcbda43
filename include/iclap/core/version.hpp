// SPDX-License-Identifier: MIT
#pragma once

/// The library version, in one place: CMake parses these three lines.
#define ICLAP_VERSION_MAJOR 0
#define ICLAP_VERSION_MINOR 1
#define ICLAP_VERSION_PATCH 0

#define ICLAP_VERSION_STRING_(a, b, c) #a "." #b "." #c
#define ICLAP_VERSION_STRING_X_(a, b, c) ICLAP_VERSION_STRING_(a, b, c)
/// "MAJOR.MINOR.PATCH" as a string literal.
#define ICLAP_VERSION_STRING \
  ICLAP_VERSION_STRING_X_(ICLAP_VERSION_MAJOR, ICLAP_VERSION_MINOR, ICLAP_VERSION_PATCH)
